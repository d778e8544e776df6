"""Random small gr1c games for the synthesis tests: a few parts drawn from small pools.

Each pooled part mentions few variables, so that unrealizable games whose cores have several
parts, each needed, are common (random formula trees are mostly true or false alone).
"""

from __future__ import annotations

import random

from tlmpc.synth.spec import InitMode

#: The parts random games are drawn from, per section (ENV: e0; SYS: s0 s1)
POOLS = {
    "ENVINIT": ["e0", "!e0", "e0 | s0"],
    "SYSINIT": ["s0", "!s0", "s0 & s1", "!s0 & !s1", "s0 | e0", "!s1", "e0 -> s0", "s1 <-> e0"],
    "ENVTRANS": ["e0' <-> !e0", "e0 -> !e0'", "s0 -> e0'"],
    "ENVGOAL": ["e0", "!e0", "e0 <-> s1"],
    "SYSTRANS": [
        "s0' <-> s0",
        "!s0",
        "s0 -> s1'",
        "s1' <-> !s1",
        "s0' -> e0",
        "!s1 | s0'",
        "s1 -> s1'",
        "!(s0 & s1)",
        "s0' <-> e0'",
    ],
    "SYSGOAL": ["s0", "s1", "s0 & !s1", "e0 -> s0", "!s0", "s1 <-> e0"],
}
MOST = {"ENVINIT": 1, "SYSINIT": 1, "ENVTRANS": 1, "ENVGOAL": 1, "SYSTRANS": 3, "SYSGOAL": 2}


def random_spc(rng: random.Random, mode: InitMode) -> str:
    """A random game in gr1c's format, its sections in a random order (a SYSINIT after the
    system's other parts is what a deletion assuming monotonicity got wrong)."""
    chosen = {name: rng.sample(pool, rng.randint(0, MOST[name])) for name, pool in POOLS.items()}
    if mode == "forall_env_exists_sys":
        # each initial condition over its own player's variables (gr1c's rule there)
        chosen["SYSINIT"] = [f for f in chosen["SYSINIT"] if "e0" not in f]
        chosen["ENVINIT"] = [f for f in chosen["ENVINIT"] if "s0" not in f]
    if mode == "one_side" and chosen["SYSINIT"]:
        chosen["ENVINIT"] = []  # at most one of them
    lead = {"ENVTRANS": "[]", "SYSTRANS": "[]", "ENVGOAL": "[]<>", "SYSGOAL": "[]<>"}
    order = list(chosen)
    rng.shuffle(order)
    lines = ["ENV: e0;", "SYS: s0 s1;"]
    for name in order:
        lines.append(
            f"{name}: " + " & ".join(f"{lead.get(name, '')}({f})" for f in chosen[name]) + ";"
        )
    return "\n".join(lines) + "\n"

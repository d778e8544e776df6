"""Controllers realise the plan: the paper's bisimulation requirement, as properties.

Every state of a triangle leaves through the planned edge, never touching the other two,
before the exit-time bound, at a speed within the bound; stay fields converge inside; the exact
simulation matches a fine RK45 integration.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp
from scipy.linalg import expm

from tlmpc.abstraction.model import Abstraction
from tlmpc.base.errors import InvalidInputError
from tlmpc.control import controllers_to_json, synthesize
from tlmpc.control.geometry import triangle_geometry
from tlmpc.control.model import StepController
from tlmpc.control.synthesize import (
    VertexProgram,
    _assign_runs,
    conic_form,
    plan_steps,
    solve_vertex_program,
    vertex_program,
)
from tlmpc.io.schema_check import validation_errors
from tlmpc.mission.model import Robot
from tlmpc.pipeline.stages import ABSTRACTION, CONTROLLERS, MISSION, WITNESS
from tlmpc.planning.model import Witness
from tlmpc.simulate.exact import _exit_step, _local_flow, _stay_step, bracketed_root
from tlmpc.simulate.matrix import expm_small


def _min_angle(v: np.ndarray) -> float:
    angles = []
    for i in range(3):
        a, b = v[(i + 1) % 3] - v[i], v[(i + 2) % 3] - v[i]
        cos = a @ b / (np.linalg.norm(a) * np.linalg.norm(b))
        angles.append(math.degrees(math.acos(max(-1.0, min(1.0, cos)))))
    return min(angles)


@st.composite
def triangles(draw: st.DrawFn) -> np.ndarray:
    """Random counter-clockwise triangles, thin and obtuse ones included (angles >= 3 deg)."""
    coords = [draw(st.floats(-5, 5)) for _ in range(6)]
    v = np.array(coords).reshape(3, 2)
    cross = (v[1, 0] - v[0, 0]) * (v[2, 1] - v[0, 1]) - (v[2, 0] - v[0, 0]) * (v[1, 1] - v[0, 1])
    assume(abs(cross) > 1e-2)
    if cross < 0:
        v = v[[0, 2, 1]]
    assume(_min_angle(v) >= 3.0)
    return v


def two_triangle_plan(v: np.ndarray, exit_edge: int, *, stay: bool) -> tuple[Abstraction, Witness]:
    """Triangle 0 = v; triangle 1 its mirror image across facet ``exit_edge``."""
    a, b = v[(exit_edge + 1) % 3], v[(exit_edge + 2) % 3]
    d = b - a
    apex = v[exit_edge]
    foot = a + ((apex - a) @ d) / (d @ d) * d
    mirror = 2 * foot - apex
    vertices = np.array([*v, mirror])
    tri0 = [0, 1, 2]
    ia, ib = (exit_edge + 1) % 3, (exit_edge + 2) % 3
    tri1 = [ib, ia, 3]  # counter-clockwise: the shared edge reversed
    neighbors = np.full((2, 3), -1, dtype=np.int64)
    neighbors[0, exit_edge] = 1
    neighbors[1, 2] = 0
    abstraction = Abstraction(
        vertices=vertices,
        triangles=np.array([tri0, tri1], dtype=np.int64),
        neighbors=neighbors,
        letter_of=np.zeros(2, dtype=np.int64),
        letters=((),),
        start=0,
        component=np.zeros(2, dtype=np.int64),
        regions={},
    )
    witness = Witness(
        prefix=(0,) if stay else (),
        cycle=(1,) if stay else (0,),
        prefix_states=(0,) if stay else (),
        cycle_states=(0,),
        word=((), ()),
        cost=0.0,
        metric="length",
        beta=1.0,
        prefix_cost=0.0,
        cycle_cost=0.0,
    )
    return abstraction, witness


def _random_point(data: st.DataObject, v: np.ndarray) -> np.ndarray:
    weights = np.array([data.draw(st.floats(0, 1)) for _ in range(3)]) + 1e-12
    weights /= weights.sum()
    return weights @ v  # type: ignore[no-any-return]


def _exit_controller(v: np.ndarray, exit_edge: int, speed: float) -> StepController:
    abstraction, witness = two_triangle_plan(v, exit_edge, stay=True)
    return synthesize(abstraction, witness, Robot(start=(0.0, 0.0), max_speed=speed)).steps[0]


@pytest.mark.slow
@settings(deadline=None, max_examples=max(15, settings().max_examples * 3 // 10))  # 60 in CI
@given(triangles(), st.integers(0, 2), st.floats(0.2, 3.0), st.data())
def test_every_state_leaves_through_the_planned_edge(
    v: np.ndarray, exit_edge: int, speed: float, data: st.DataObject
) -> None:
    controller = _exit_controller(v, exit_edge, speed)
    geometry = triangle_geometry(v)
    # speed bound at random points of the triangle (the field is affine: vertices suffice,
    # random points check the interpolation)
    for _ in range(5):
        x = _random_point(data, v)
        assert np.linalg.norm(controller.gain @ x + controller.offset) <= speed * (1 + 1e-7)
    x0 = _random_point(data, v)
    times, points = _exit_step(controller, x0)
    crossing_time, exit_point = times[-1], points[-1]
    assert crossing_time <= controller.exit_time_bound * (1 + 1e-9)
    # the exit point is on the planned edge, strictly between its end points
    lam = geometry.barycentric(exit_point)
    assert abs(lam[exit_edge]) <= 1e-9
    # before the crossing the trajectory stays inside, away from the two other edges
    augmented = np.block([[controller.gain, controller.offset[:, None]], [np.zeros((1, 3))]])
    for t in np.linspace(0.0, crossing_time, 50)[1:-1]:
        inside = geometry.barycentric((expm(t * augmented) @ [*x0, 1.0])[:2])
        others = [j for j in range(3) if j != exit_edge]
        assert min(inside[j] for j in others) > -1e-9
        assert inside[exit_edge] > -1e-9
    for j in (j for j in range(3) if j != exit_edge):
        assert lam[j] > -1e-9


@settings(deadline=None, max_examples=40)
@given(triangles(), st.integers(0, 2), st.data())
def test_exact_simulation_matches_rk45(v: np.ndarray, exit_edge: int, data: st.DataObject) -> None:
    controller = _exit_controller(v, exit_edge, 1.0)
    x0 = _random_point(data, v)
    times, points = _exit_step(controller, x0)
    geometry = triangle_geometry(v)
    normal, offset = geometry.normals[exit_edge], geometry.offsets[exit_edge]

    def crossing(_: float, x: np.ndarray) -> float:
        return float(normal @ x - offset)

    crossing.terminal = True  # type: ignore[attr-defined]
    crossing.direction = 1  # type: ignore[attr-defined]
    if crossing(0.0, x0) >= -1e-12:
        return  # starts on the exit edge: nothing to integrate
    solution = solve_ivp(
        lambda _t, x: controller.gain @ x + controller.offset,
        (0.0, 2 * controller.exit_time_bound + 1.0),
        x0,
        method="RK45",
        rtol=1e-12,
        atol=1e-13,
        events=crossing,
        dense_output=True,
    )
    assert solution.t_events[0].size == 1
    assert solution.t_events[0][0] == pytest.approx(times[-1], rel=1e-8, abs=1e-9)
    assert np.allclose(solution.y_events[0][0], points[-1], atol=1e-8)
    assert times == sorted(times)
    for t, point in zip(times[:-1], points[:-1], strict=True):
        assert 0.0 < t < times[-1]
        assert np.allclose(solution.sol(t), point, atol=1e-8)


@settings(deadline=None, max_examples=40)
@given(triangles(), st.data())
def test_stay_fields_converge_inside(v: np.ndarray, data: st.DataObject) -> None:
    abstraction, witness = two_triangle_plan(v, 0, stay=False)
    witness = Witness(
        prefix=(),
        cycle=(0,),
        prefix_states=(),
        cycle_states=(0,),
        word=((),),
        cost=0.0,
        metric="length",
        beta=1.0,
        prefix_cost=0.0,
        cycle_cost=0.0,
    )
    controller = synthesize(abstraction, witness, Robot(start=(0.0, 0.0))).steps[0]
    assert controller.exit_edge is None
    assert controller.target is not None
    assert np.max(np.linalg.eigvals(controller.gain).real) < 0, "K is Hurwitz"
    target = np.asarray(controller.target)
    assert np.allclose(controller.gain @ target + controller.offset, 0.0, atol=1e-7)
    geometry = triangle_geometry(v)
    x0 = _random_point(data, v)
    _, points = _stay_step(controller, x0, 1.0)
    for point in points:
        assert geometry.barycentric(point).min() > -1e-9
    distance = float(np.linalg.norm(x0 - target))
    assert np.linalg.norm(points[-2] - target) <= 1e-5 * max(1.0, distance)


def test_small_matrix_exponential_matches_scipy() -> None:
    rng = np.random.default_rng(7)
    for _ in range(300):
        matrix = np.zeros((3, 3))
        matrix[:2] = rng.normal(size=(2, 3)) * rng.uniform(0.01, 5.0)
        ours, reference = expm_small(matrix), expm(matrix)
        assert np.abs(ours - reference).max() <= 1e-10 * np.abs(reference).max()
        assert np.array_equal(ours[2], [0.0, 0.0, 1.0])  # the affine structure is exact


def test_a_bounce_is_rejected() -> None:
    v = np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]])
    abstraction, _ = two_triangle_plan(v, 0, stay=True)
    bounce = Witness(
        prefix=(0, 1),
        cycle=(0,),
        prefix_states=(0, 0),
        cycle_states=(0,),
        word=((), (), ()),
        cost=0.0,
        metric="length",
        beta=1.0,
        prefix_cost=0.0,
        cycle_cost=0.0,
    )
    with pytest.raises(InvalidInputError) as caught:
        synthesize(abstraction, bounce, Robot(start=(0.5, 0.5)))
    assert caught.value.diagnostics[0].code == "C002"


def test_continuity_and_jumps_on_a_real_plan(specs_dir: object) -> None:
    from pathlib import Path

    from tlmpc.pipeline.stages import compile_mission

    result = compile_mission(Path(str(specs_dir)) / "patrol.yaml", until="control")
    controllers = result.compilation.get(CONTROLLERS)
    document = controllers_to_json(controllers)
    assert validation_errors(document, "controllers") == []
    jumped = {(j.step, j.vertex) for j in controllers.jumps}
    abstraction = result.compilation.get(ABSTRACTION)
    steps = controllers.steps
    shared_equal = 0
    for k in range(1, len(steps)):
        previous, current = steps[k - 1], steps[k]
        if current.exit_edge is None:
            continue
        for i, vertex in enumerate(abstraction.triangles[current.triangle].tolist()):
            corners = abstraction.triangles[previous.triangle].tolist()
            if vertex in corners and (k, vertex) not in jumped:
                j = corners.index(vertex)
                assert np.allclose(previous.velocities[j], current.velocities[i], atol=1e-6)
                shared_equal += 1
    assert shared_equal > 0
    assert all(c.exit_speed > 0 for c in steps)


def test_lasso_without_prefix_loops_from_the_second_lap(specs_dir: object) -> None:
    """A cycle that starts in the start triangle: lap one is the transient, lap two the loop."""
    import dataclasses
    from pathlib import Path

    from tlmpc.pipeline.stages import compile_mission
    from tlmpc.simulate import simulate, trace_to_json
    from tlmpc.verify import verify_document

    result = compile_mission(Path(str(specs_dir)) / "patrol.yaml", until="plan")
    abstraction, witness, mission = (
        result.compilation.get(ABSTRACTION),
        result.compilation.get(WITNESS),
        result.compilation.get(MISSION),
    )
    loop = dataclasses.replace(witness, prefix=(), prefix_states=())
    x, y = abstraction.corners(loop.cycle[0]).mean(axis=0).tolist()
    robot = dataclasses.replace(mission.robot, start=(x, y))
    moved = dataclasses.replace(mission, robot=robot)
    controllers = synthesize(abstraction, loop, robot)
    assert controllers.loop_start == 0
    trace = simulate(abstraction, controllers, moved)
    assert trace.loop_start is not None
    assert 0 < trace.loop_start < len(trace.times) - 1
    # the loop starts and ends at the crossing into the cycle's first triangle
    assert trace.triangles[trace.loop_start] == loop.cycle[0]
    assert trace.triangles[-1] == loop.cycle[0]
    assert verify_document(trace_to_json(trace, moved)).satisfied


def _cvxpy_optimum(program: VertexProgram) -> float:
    """The same program stated in cvxpy, an independent canonicalisation, solved by Clarabel."""
    import cvxpy as cp

    z = cp.Variable(program.inequality.shape[1])
    floor = cp.Variable()
    velocities = cp.reshape(z[: 2 * program.runs], (program.runs, 2), order="C")
    speeds = z[2 * program.runs :]
    constraints = [
        program.inequality.toarray() @ z >= 0,
        cp.norm(velocities, 2, axis=1) <= program.max_speed,
        speeds >= floor,
    ]
    if program.equality is not None:
        constraints.append(program.equality.toarray() @ z == 0)
    problem = cp.Problem(cp.Maximize(floor + 0.1 * cp.sum(speeds) / program.steps), constraints)
    problem.solve(solver=cp.CLARABEL)
    assert problem.status == "optimal"
    return float(problem.value)


@pytest.mark.parametrize(
    ("spec", "max_speed"),
    [("example1", 1.0), ("example7", 0.5), ("patrol", 2.0), ("reach-avoid", 1.0)],
)
def test_clarabel_conic_form_matches_cvxpy(specs_dir: object, spec: str, max_speed: float) -> None:
    from pathlib import Path

    from tlmpc.pipeline.stages import compile_mission

    result = compile_mission(Path(str(specs_dir)) / f"{spec}.yaml", until="plan")
    abstraction, witness = result.compilation.get(ABSTRACTION), result.compilation.get(WITNESS)
    steps, loop_start = plan_steps(abstraction, witness)
    _assign_runs(abstraction, steps, loop_start)
    program, _ = vertex_program(steps, max_speed)
    velocities, speeds = solve_vertex_program(program)
    z = np.concatenate([velocities.ravel(), speeds])
    tolerance = 1e-6 * max_speed
    assert (program.inequality.toarray() @ z).min() >= -tolerance
    if program.equality is not None:
        assert np.abs(program.equality.toarray() @ z).max() <= tolerance
    assert np.linalg.norm(velocities, axis=1).max() <= max_speed * (1 + 1e-7)
    ours = program.objective(z, float(speeds.min()))
    assert ours == pytest.approx(_cvxpy_optimum(program), rel=1e-6, abs=1e-8)
    assert speeds.min() > 0


@settings(deadline=None, max_examples=200)
@given(
    st.floats(0.001, 0.999),
    st.sampled_from([1, 2, 3, 5, 9]),
    st.floats(1e-6, 1e3),
    st.floats(0.0, 50.0),
)
def test_bracketed_root_matches_brentq(root: float, power: int, scale: float, tilt: float) -> None:
    from scipy.optimize import brentq

    def function(x: float) -> float:
        # monotone, flat or steep near the root, with an exponential factor
        return scale * math.copysign(abs(x - root) ** power, x - root) * math.exp(tilt * x)

    ours = bracketed_root(function, 0.0, 1.0)
    assert 0.0 <= ours <= 1.0
    assert function(ours) >= 0.0
    reference = brentq(function, 0.0, 1.0, xtol=1e-14, rtol=1e-14, maxiter=1000)
    assert ours == pytest.approx(reference, abs=1e-12)


@settings(deadline=None, max_examples=40)
@given(triangles(), st.integers(0, 2), st.sampled_from([1e3, -4e4, 2.5e5]), st.data())
def test_exit_steps_far_from_the_origin_are_translates(
    v: np.ndarray, exit_edge: int, shift: float, data: st.DataObject
) -> None:
    """Far from the origin the global offset dominates the flow's matrix; an exit step must
    still be the translate of the same step near the origin (in the global frame the crossing
    time drifted by ~1e-6 at a shift of 2.5e5)."""
    near = _exit_controller(v, exit_edge, 1.0)
    # The same field, moved: x' = K (x - shift) + g.
    far = dataclasses.replace(
        near, vertices=near.vertices + shift, offset=near.offset - near.gain @ [shift, shift]
    )
    x0 = _random_point(data, v)
    near_times, near_points = _exit_step(near, x0)
    far_times, far_points = _exit_step(far, x0 + shift)
    # rounding of coordinates of size |shift| moves the crossing by ~1e-16 |shift| / speed
    assert far_times[-1] == pytest.approx(near_times[-1], rel=1e-9, abs=1e-11 * abs(shift))
    assert np.allclose(far_points[-1] - shift, near_points[-1], atol=1e-12 * abs(shift) + 1e-12)


@settings(deadline=None, max_examples=60)
@example([0.5, -0.2, 0.1, 0.3, 0.4, -0.6], [0.5, -0.5], 0.05)  # the polynomial path
@example([3.0, -2.0, 3.0, 1.5, -3.0, 2.5], [1.0, 2.0], 2.5)  # |reach M| > SERIES_RADIUS
@given(
    st.lists(st.floats(-3.0, 3.0), min_size=6, max_size=6),
    st.lists(st.floats(-2.0, 2.0), min_size=2, max_size=2),
    st.floats(0.01, 3.0),
)
def test_local_flow_matches_scipy_on_both_paths(
    entries: list[float], start: list[float], reach: float
) -> None:
    """The exit search's flow from a grid state: the Taylor polynomial when |reach M| is small,
    the matrix exponential otherwise; both must be exp(sM) base."""
    matrix = np.zeros((3, 3))
    matrix[:2] = np.reshape(entries, (2, 3))
    base = np.array([*start, 1.0])
    normal = np.array([0.6, 0.8])
    point, height = _local_flow(matrix, base, reach, normal, 0.25)
    for s in (0.0, 0.3 * reach, reach):
        exact = expm(s * matrix) @ base
        assert np.allclose(point(s), exact, rtol=1e-10, atol=1e-10)
        assert height(s) == pytest.approx(normal @ exact[:2] - 0.25, rel=1e-10, abs=1e-10)


def _outward_normal(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Unit outward normal of edge a->b of a counter-clockwise triangle (own geometry)."""
    d = b - a
    n = np.array([d[1], -d[0]])
    return n / float(np.linalg.norm(n))


@pytest.mark.parametrize("spec", ["example1.yaml", "example6.yaml", "reach-avoid.yaml"])
def test_solved_fields_meet_the_stated_vertex_conditions(specs_dir: object, spec: str) -> None:
    """Re-check every step after solving: exit at the reported speed, invariance, speed bound."""
    from pathlib import Path

    from tlmpc.pipeline.stages import compile_mission

    result = compile_mission(Path(str(specs_dir)) / spec, until="control")
    controllers = result.compilation.get(CONTROLLERS)
    tolerance = 1e-6 * controllers.max_speed
    for c in controllers.steps:
        v = c.vertices
        for i in range(3):  # the field is affine: it takes the vertex velocities at the vertices
            assert np.allclose(c.gain @ v[i] + c.offset, c.velocities[i], atol=tolerance)
            assert float(np.linalg.norm(c.velocities[i])) <= controllers.max_speed + tolerance
        if c.exit_edge is None:
            continue
        normals = [_outward_normal(v[(j + 1) % 3], v[(j + 2) % 3]) for j in range(3)]
        assert c.exit_speed > 0
        for i in range(3):
            assert normals[c.exit_edge] @ c.velocities[i] >= c.exit_speed - tolerance
            for facet in range(3):
                if facet in (i, c.exit_edge):
                    continue
                # strictly inward: the field never slides along or leaves by another facet
                assert -(normals[facet] @ c.velocities[i]) > tolerance


@settings(deadline=None, max_examples=30)
@given(triangles(), st.integers(0, 2), st.floats(0.2, 3.0))
def test_exit_speed_is_the_best_the_vertex_conditions_allow(
    v: np.ndarray, exit_edge: int, speed: float
) -> None:
    """An independent program from the raw triangle: no field does better than the vertex
    program's (the fields that follow the channel trade some of it for the path)."""
    import cvxpy as cp

    abstraction, witness = two_triangle_plan(v, exit_edge, stay=True)
    robot = Robot(start=(0.0, 0.0), max_speed=speed)
    controllers = synthesize(abstraction, witness, robot, follow=False)
    step = controllers.steps[0]
    normals = [_outward_normal(v[(j + 1) % 3], v[(j + 2) % 3]) for j in range(3)]
    w = cp.Variable((3, 2))
    s = cp.Variable()
    constraints = []
    for i in range(3):
        constraints.append(cp.norm(w[i]) <= speed)
        constraints.append(normals[exit_edge] @ w[i] >= s)
        for facet in range(3):
            if facet not in (i, exit_edge):
                constraints.append(-(normals[facet] @ w[i]) >= controllers.margin * s)
    best = cp.Problem(cp.Maximize(s), constraints).solve(solver=cp.CLARABEL)
    assert best is not None
    assert best > 0
    assert step.exit_speed >= float(best) * (1 - 1e-5)


@settings(
    deadline=None,
    max_examples=30,
    # thin triangles and boundary points are filtered out; older hypothesis releases count
    # that against the strategy
    suppress_health_check=[HealthCheck.filter_too_much],
)
@given(triangles(), st.integers(0, 2), st.integers(1, 2), st.data())
def test_a_field_leaving_by_an_unplanned_facet_is_reported(
    v: np.ndarray, exit_edge: int, shift: int, data: st.DataObject
) -> None:
    """The simulator never snaps a wrong exit onto the planned edge."""
    from tlmpc.base.errors import SolverError

    controller = _exit_controller(v, exit_edge, 1.0)
    wrong = dataclasses.replace(controller, exit_edge=(exit_edge + shift) % 3)
    x0 = _random_point(data, v)
    geometry = triangle_geometry(v)
    assume(geometry.barycentric(x0).min() > 1e-3)  # strictly inside: the real exit comes later
    with pytest.raises(SolverError) as caught:
        _exit_step(wrong, x0)
    # C031 when it crosses the wrong facet within the horizon, C010 when the horizon (set by
    # the planned edge) ends first: an error either way, never a crossing snapped into place
    assert caught.value.diagnostics[0].code in {"C031", "C010"}


@pytest.mark.parametrize("scale", [1.0, 1e-3, 1e4])
def test_a_dip_across_another_facet_before_the_exit_is_reported(scale: float) -> None:
    """An outward spiral that dips below the bottom edge, comes back in and then leaves
    through the planned hypotenuse: the first exit was the wrong one (C031), even though the
    later crossing lies on the planned edge and would snap cleanly."""
    from tlmpc.base.errors import SolverError

    v = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]) * scale
    center = np.array([0.45, 0.4]) * scale
    gain = np.array([[0.1, -1.0], [1.0, 0.1]])  # x' = K (x - center): turn, slowly grow
    angle = math.radians(-120.0)
    x0 = center + 0.39 * scale * np.array([math.cos(angle), math.sin(angle)])
    controller = StepController(
        step=0,
        triangle=0,
        exit_edge=0,  # the hypotenuse, opposite vertex 0
        next_triangle=1,
        vertices=v,
        velocities=(v - center) @ gain.T,
        gain=gain,
        offset=-gain @ center,
        exit_speed=0.3 * scale,  # a horizon long enough for the spiral to reach the exit
        exit_time_bound=10.0,
    )
    # the definition, by a fine RK45 integration: below y = 0 first, then across x + y = 1
    # inside the edge's span
    run = solve_ivp(
        lambda _, x: gain @ (x - center), (0.0, 1.6), x0, max_step=1e-3, rtol=1e-10, atol=1e-12
    )
    bottom = np.flatnonzero(run.y[1] < -1e-3 * scale)
    across = np.flatnonzero(run.y[0] + run.y[1] > scale)
    assert bottom.size
    assert across.size
    assert bottom[-1] < across[0]
    assert 0 < run.y[0][across[0]] < scale  # back in, then out within the edge's span
    assert run.y[1][across[0]] > 0
    with pytest.raises(SolverError) as caught:
        _exit_step(controller, x0)
    assert caught.value.diagnostics[0].code == "C031"


@settings(deadline=None, max_examples=30)
@given(triangles(), st.integers(0, 2))
def test_the_recheck_finds_every_broken_vertex_condition(v: np.ndarray, exit_edge: int) -> None:
    """The re-check after solving rejects a field that breaks any one vertex condition."""
    from tlmpc.control.geometry import affine_law
    from tlmpc.control.synthesize import violated_condition

    controller = _exit_controller(v, exit_edge, 1.0)
    assert violated_condition(controller, 1.0) is None
    geometry = triangle_geometry(v)

    def with_velocity(vertex: int, velocity: np.ndarray) -> StepController:
        w = controller.velocities.copy()
        w[vertex] = velocity
        gain, offset = affine_law(v, w)
        return dataclasses.replace(controller, velocities=w, gain=gain, offset=offset)

    too_fast = with_velocity(
        0, controller.velocities[0] * 1.01 / np.linalg.norm(controller.velocities[0])
    )
    assert violated_condition(too_fast, 1.0) is not None
    for vertex in range(3):
        for facet in range(3):
            if facet == vertex:
                continue
            tangent = v[(facet + 2) % 3] - v[(facet + 1) % 3]
            sliding = with_velocity(vertex, 0.5 * tangent / np.linalg.norm(tangent))
            # Along a facet: neither across the exit nor strictly inside another facet.
            assert violated_condition(sliding, 1.0) is not None, (vertex, facet)
    backwards = with_velocity(exit_edge, -0.5 * geometry.normals[exit_edge])
    assert violated_condition(backwards, 1.0) is not None


def _scipy_constraints(program: VertexProgram) -> object:
    """The constraint matrix assembled with scipy.sparse blocks (the former construction)."""
    import scipy.sparse as sp

    def matrix(t: object) -> object:
        return sp.csr_matrix((t.values, (t.rows, t.cols)), shape=t.shape)  # type: ignore[attr-defined]

    count, n_steps = program.runs, program.steps
    size = 2 * count + n_steps
    floor_column = sp.csr_matrix(([1.0] * n_steps, (range(n_steps), [0] * n_steps)), (n_steps, 1))
    speeds = sp.hstack([sp.csr_matrix((n_steps, 2 * count)), -sp.identity(n_steps)])
    blocks = []
    if program.equality is not None:
        equality = matrix(program.equality)
        blocks.append(sp.hstack([equality, sp.csr_matrix((program.equality.shape[0], 1))]))
    rows = program.inequality.shape[0]
    blocks.append(sp.hstack([-matrix(program.inequality), sp.csr_matrix((rows, 1))]))  # type: ignore[operator]
    blocks.append(sp.hstack([speeds, floor_column]))
    soc_rows = np.arange(3 * count).reshape(count, 3)[:, 1:].ravel()
    blocks.append(
        sp.csr_matrix(
            (-np.ones(2 * count), (soc_rows, np.arange(2 * count))), shape=(3 * count, size + 1)
        )
    )
    return sp.vstack(blocks, format="csc")


@pytest.mark.parametrize("spec", ["example1", "example7", "patrol", "reach-avoid"])
def test_conic_form_is_the_scipy_assembly(specs_dir: object, spec: str) -> None:
    """Clarabel gets the same CSC arrays, entry for entry (explicit zeros and signs of zero
    included), as from the scipy.sparse blocks it was built with before."""
    from pathlib import Path

    from tlmpc.pipeline.stages import compile_mission

    result = compile_mission(Path(str(specs_dir)) / f"{spec}.yaml", until="plan")
    abstraction, witness = result.compilation.get(ABSTRACTION), result.compilation.get(WITNESS)
    steps, loop_start = plan_steps(abstraction, witness)
    _assign_runs(abstraction, steps, loop_start)
    program, _ = vertex_program(steps, 1.0)
    ours = conic_form(program).constraints
    theirs = _scipy_constraints(program)
    assert ours.shape == theirs.shape  # type: ignore[attr-defined]
    assert np.array_equal(ours.indptr, theirs.indptr)  # type: ignore[attr-defined]
    assert np.array_equal(ours.indices, theirs.indices)  # type: ignore[attr-defined]
    assert np.array_equal(ours.data, theirs.data)  # type: ignore[attr-defined]
    assert np.array_equal(np.signbit(ours.data), np.signbit(theirs.data))  # type: ignore[attr-defined]

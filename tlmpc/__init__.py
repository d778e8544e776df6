"""tlmpc: a temporal logic motion planning compiler and verifier.

The method is Fainekos, Kress-Gazit and Pappas, "Temporal Logic Motion Planning for Mobile
Robots" (ICRA 2005): triangulate the workspace, plan on the transition system with an LTL
automaton, realise the plan with affine feedback per triangle, and check the trajectory.
"""

__version__ = "0.1.0"

"""Profile surfaces shared by the analytic-surface tests: extruded and revolved, convex and concave arcs,
straight segments and a sharp corner, placed off the coordinate axes."""

import numpy as np

from covcontact.contact import Profile


def profiles(motion):
    ax = np.array([1.0, 1.0, 0.3]) / np.linalg.norm([1.0, 1.0, 0.3])
    u = np.cross(ax, [0.0, 0.0, 1.0])
    u /= np.linalg.norm(u)
    return {
        "ext_valley": Profile([(-3.0, 2.0), (-0.5, -1.0), (2.0, -0.5), (3.0, 2.0)], [1.5, 0.8],
                              extrude={"axis": tuple(ax), "origin": (0.0, 0.5, 0.0), "u": tuple(u)},
                              motion=motion),
        "ext_ridge": Profile([(3.0, -2.0), (0.5, 0.6), (-1.0, 0.0), (-3.0, -2.0)], [2.0, 0.0],
                             extrude={"axis": (0.0, 1.0, 0.0), "origin": (0.3, 0.0, 0.2)}, motion=motion),
        "rev_punch": Profile([(3.0, 3.0), (1.5, 0.0), (0.0, 0.0)], [1.2],
                             revolve={"axis": (0.2, 0.1, 1.0), "center": (0.2, -0.1, 0.6)}, motion=motion),
        "rev_die": Profile([(0.0, -1.0), (1.0, -1.0), (1.4, 1.0), (4.0, 1.2)], [0.8, 1.0],
                           revolve={"axis": (0.0, 0.0, 1.0), "center": (0.2, -0.1, 0.0)}, motion=motion),
    }

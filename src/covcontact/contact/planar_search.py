"""The closest point of each slave on a master curve in the plane, compiled (:func:`.planar.closest_points` gives
the rules and builds the arrays; docs/theory.md section 28).

Per slave: the segments of the corner nodes near it (``near_ptr``, ``near_k``: its corners, positions in the
curve's sorted ``nodes``; ``node_ptr``, ``node_segs``: each corner's segments in increasing order), the one of
smallest |g| among those holding its projection (within ``tol`` of their ends), after the segment it keeps
(``keep``, up to ``keep_band``); none: the nearest corner between two segments. Self-contact (``self_mode``) skips the
slave's own segments (``exclude``, -1 padded) and those whose normal makes a cosine of ``cos_max`` or more with its
own (``own``), and takes a vertex only in front of the slave (within ``front_cos`` of -own) and not its own node.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .planar_kernels import project_on_segment

FACET, VERTEX = 1, 2


@njit(cache=True)
def _excluded(exclude, i, s):
    for j in range(exclude.shape[1]):
        if exclude[i, j] == s:
            return True
    return False


@njit(cache=True)
def closest_core(xe, xs, segments, nodes, node_ptr, node_segs, near_ptr, near_k, keep, keep_band, tol, self_mode,
                 exclude, own, cos_max, normals, front_cos, kind, seg, xi, g, vert, sign):
    """Fill kind (0 none, FACET, VERTEX), seg, xi, g, vert, sign of every slave xs (ns, 3); see the module."""
    ns = xs.shape[0]
    nen = segments.shape[1]
    xseg = np.empty((nen, 3))
    xsi = np.empty(3)
    for i in range(ns):
        a = near_ptr[i]
        b = near_ptr[i + 1]
        if a == b:
            continue
        for p in range(3):
            xsi[p] = xs[i, p]
        if keep[i] >= 0:
            s = keep[i]
            for q in range(nen):
                for p in range(3):
                    xseg[q, p] = xe[segments[s, q], p]
            z, gap, ok = project_on_segment(xseg, xsi, 0.0)
            if ok and abs(z) <= 1.0 + keep_band:
                kind[i] = FACET
                seg[i] = s
                xi[i] = z
                g[i] = gap
                continue
        count = 0
        for m in range(a, b):
            k = near_k[m]
            count += node_ptr[k + 1] - node_ptr[k]
        cand = np.empty(count, dtype=np.int64)
        c = 0
        for m in range(a, b):
            k = near_k[m]
            for j in range(node_ptr[k], node_ptr[k + 1]):
                cand[c] = node_segs[j]
                c += 1
        cand = np.unique(cand)
        best = np.inf
        for s in cand:
            if self_mode:
                if _excluded(exclude, i, s):
                    continue
                if normals[s, 0] * own[i, 0] + normals[s, 1] * own[i, 1] >= cos_max[i]:
                    continue
            for q in range(nen):
                for p in range(3):
                    xseg[q, p] = xe[segments[s, q], p]
            z, gap, ok = project_on_segment(xseg, xsi, 0.0)
            if ok and abs(z) <= 1.0 + tol and abs(gap) < best:
                best = abs(gap)
                kind[i] = FACET
                seg[i] = s
                xi[i] = min(max(z, -1.0), 1.0)
                g[i] = gap
        if kind[i] != 0:
            continue
        # no segment holds the projection: the nearest vertex between two segments
        dist = np.empty(b - a)
        for m in range(a, b):
            v = nodes[near_k[m]]
            d0 = xe[v, 0] - xs[i, 0]
            d1 = xe[v, 1] - xs[i, 1]
            dist[m - a] = np.sqrt(d0 * d0 + d1 * d1)
        order = np.argsort(dist, kind="mergesort")
        for o in order:
            k = near_k[a + o]
            if node_ptr[k + 1] - node_ptr[k] != 2:
                continue
            v = nodes[k]
            s0 = node_segs[node_ptr[k]]
            s1 = node_segs[node_ptr[k] + 1]
            d0 = xs[i, 0] - xe[v, 0]
            d1 = xs[i, 1] - xe[v, 1]
            dn = np.sqrt(d0 * d0 + d1 * d1)
            if self_mode:  # (a vertex in front of the slave only, never its own node)
                if dn == 0.0 or -(d0 * own[i, 0] + d1 * own[i, 1]) < front_cos * dn or \
                        (_excluded(exclude, i, s0) and _excluded(exclude, i, s1)):
                    continue
            sg = 1.0 if d0 * (normals[s0, 0] + normals[s1, 0]) + d1 * (normals[s0, 1] + normals[s1, 1]) >= 0.0 \
                else -1.0
            kind[i] = VERTEX
            seg[i] = s0
            vert[i] = v
            sign[i] = sg
            xi[i] = -1.0 if segments[s0, 0] == v else 1.0
            g[i] = sg * dn
            break

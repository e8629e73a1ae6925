"""Loose vertices and edges carried to the limit mesh, as Blender's Subdivision Surface carries
them (blenkernel/intern/subdiv_mesh.cc, subdiv_mesh_vert_of_loose_edge):

* a vertex in no face keeps its place, except inside a chain of loose edges;
* each loose edge becomes 2^levels edges; its points at u = i / 2^levels are the uniform cubic
  B-spline (Blender's key_curve_position_weights, KEY_BSPLINE) of four points: the edge's ends,
  and beyond each end the far end of the other edge there when that end has exactly two edges,
  else the end mirrored (2 a - b); so a chain of loose edges is smoothed, its ends stay;
* an end that lies on a face is the limit surface's vertex there (a corner of the surface:
  cage.Cage.loose_edge_ends, sync._plan_for);
* point attributes along a loose edge are mixed linearly between its ends.

`WithLoose` wraps a plan (native.Plan) of a cage that has a loose part: its outputs (positions,
normals, edges, per-vertex data, sizes) carry the loose vertices after the limit's and the loose
edges after the limit's, so every writer of the limit mesh (proxies.py, attrs.py) writes them as
part of it. Their normals are 0 (no face uses them).
"""
import numpy as np


def _bspline(u):
    """The four weights of the uniform cubic B-spline at u (rows of an (k, 4) array)."""
    u = np.asarray(u, np.float64)
    t2, t3 = u * u, u * u * u
    return np.stack([-t3 / 6 + t2 / 2 - u / 2 + 1 / 6, t3 / 2 - t2 + 2 / 3,
                     -t3 / 2 + t2 / 2 + u / 2 + 1 / 6, t3 / 6], axis=-1)


class Loose:
    """The loose part of a cage at `levels`: one output row per vertex in no face (vertex
    order), then 2^levels - 1 rows per loose edge (edge order); `edges` joins them, with the
    ends that lie on faces given as -1 - (cage vertex)."""

    def __init__(self, cage, levels):
        nv = cage.num_verts
        on_face = np.zeros(nv, bool)
        on_face[cage.face_verts] = True
        used = np.zeros(cage.num_edges, bool)
        used[cage.loop_edges] = True
        E = np.asarray(cage.edge_verts, np.int64).reshape(-1, 2)[~used]
        self.free = np.flatnonzero(~on_face)
        self.empty = not len(E) and not len(self.free)
        n = 2 ** max(int(levels), 0)
        deg = np.bincount(E.ravel(), minlength=nv)
        # at a vertex in no face with exactly two edges, each edge's neighbour beyond it is the
        # other edge's far end
        other = np.full((len(E), 2), -1, np.int64)
        by_vert = {}
        for i, (a, b) in enumerate(E):
            by_vert.setdefault(int(a), []).append((i, 0))
            by_vert.setdefault(int(b), []).append((i, 1))
        for v, uses in by_vert.items():
            if deg[v] == 2 and not on_face[v] and len(uses) == 2:
                (i, s), (j, t) = uses
                other[i, s] = E[j, 1 - t]
                other[j, t] = E[i, 1 - s]
        idx, wts, mix = [], [], []  # position rows; per-vertex data rows (a, b, u)

        def row(k, u):
            a, b = E[k]
            fa, fb = other[k]
            w = _bspline(u)
            w0, w1, w2, w3 = (w[..., j] for j in range(4))
            wa = w1 + np.where(fa < 0, 2 * w0, 0.0) - np.where(fb < 0, w3, 0.0)
            wb = w2 + np.where(fb < 0, 2 * w3, 0.0) - np.where(fa < 0, w0, 0.0)
            i4 = np.stack(np.broadcast_arrays(fa if fa >= 0 else a, a, b, fb if fb >= 0 else b), -1)
            w4 = np.stack([np.where(fa < 0, 0.0, w0), wa, wb, np.where(fb < 0, 0.0, w3)], -1)
            return i4, w4

        first = {}
        for i, (a, b) in enumerate(E):
            first.setdefault(int(a), (i, 0.0))
            first.setdefault(int(b), (i, 1.0))
        for v in self.free:  # in no face: on a loose edge, its end of that edge's curve
            if int(v) in first:
                k, u = first[int(v)]
                i4, w4 = row(k, np.array([u]))
            else:
                i4, w4 = np.array([[v, v, v, v]]), np.array([[1.0, 0.0, 0.0, 0.0]])
            idx.append(i4.reshape(1, 4))
            wts.append(w4.reshape(1, 4))
            mix.append(np.array([[v, v, 0.0]]))
        slot = np.full(nv, -1, np.int64)
        slot[self.free] = np.arange(len(self.free))
        inner = np.arange(1, n) / n
        edges = []
        base = len(self.free)
        for k, (a, b) in enumerate(E):
            if n > 1:
                i4, w4 = row(k, inner)
                idx.append(np.broadcast_to(i4, (n - 1, 4)))
                wts.append(w4)
                mix.append(np.stack([np.full(n - 1, a), np.full(n - 1, b), inner], -1))
            ends = [slot[a] if slot[a] >= 0 else -1 - a, slot[b] if slot[b] >= 0 else -1 - b]
            chain = [ends[0]] + list(range(base, base + n - 1)) + [ends[1]]
            edges += list(zip(chain[:-1], chain[1:]))
            base += n - 1
        self.idx = np.concatenate(idx) if idx else np.zeros((0, 4), np.int64)
        self.wts = np.concatenate(wts) if wts else np.zeros((0, 4))
        self.mix = np.concatenate(mix) if mix else np.zeros((0, 3))
        self.edges = np.array(edges, np.int64).reshape(-1, 2)
        self.on_face_ends = np.unique(-1 - self.edges[self.edges < 0])
        self.rows = len(self.idx)

    def positions(self, P):
        P = np.asarray(P, np.float64).reshape(-1, 3)
        return np.einsum("kj,kjc->kc", self.wts, P[self.idx])

    def data(self, D):
        D = np.asarray(D, np.float64)
        a, b, u = self.mix[:, 0].astype(np.int64), self.mix[:, 1].astype(np.int64), self.mix[:, 2:3]
        return (1.0 - u) * D[a] + u * D[b]


class WithLoose:
    """A plan whose outputs carry the cage's loose part (see the module's text)."""

    def __init__(self, plan, cage, part):
        self._plan = plan
        self._loose = part
        self._cage_positions = np.asarray(cage.positions, np.float64)
        self._face_end_out = None  # limit output vertex of each loose-edge end on a face
        self.sizes = dict(plan.sizes)
        self.sizes["num_verts"] += self._loose.rows
        self.sizes["num_edges"] = self.sizes.get("num_edges", 0) + len(self._loose.edges)

    def __getattr__(self, name):  # everything else is the plan's
        return getattr(self._plan, name)

    def evaluate(self, positions=None, topology=True, curvature=False):
        res = self._plan.evaluate(positions, topology=topology, curvature=curvature)
        P = self._cage_positions if positions is None else positions
        lz = self._loose
        out = dict(res)
        n = len(res["positions"])
        out["positions"] = np.concatenate([res["positions"], lz.positions(P)])
        out["normals"] = np.concatenate([res["normals"], np.zeros((lz.rows, 3))])
        if "curvatures" in res:  # loose vertices and edge points: no surface
            out["curvatures"] = np.concatenate([res["curvatures"], np.full((lz.rows, 2), np.nan)])
        if self._face_end_out is None and len(lz.on_face_ends):
            # the surface's vertex at a loose edge's end is a corner: the cage vertex itself
            # (to rounding), the limit vertex nearest to it
            Q = np.asarray(P, np.float64).reshape(-1, 3)[lz.on_face_ends]
            lim = res["positions"]
            self._face_end_out = np.array([int(np.argmin(((lim - q) ** 2).sum(1))) for q in Q])
        if "edge_verts" in res:
            e = lz.edges.copy()
            on = e < 0
            if on.any():
                e[on] = self._face_end_out[np.searchsorted(lz.on_face_ends, -1 - e[on])]
            e[~on] += n
            out["edge_verts"] = np.concatenate([res["edge_verts"], e.astype(np.int32)])
            out["loose_edges"] = e.astype(np.int32)
        return out

    def evs(self):
        return self._plan.evs()  # loose elements come after the surface's vertices

    def evaluate_vertex_data(self, data):
        base = self._plan.evaluate_vertex_data(data)
        return np.concatenate([base, self._loose.data(data)])

    def close(self):
        self._plan.close()


def unwrap(plan):
    """The native plan inside (a plan made with options.previous consumes the plan itself, not a wrapper)."""
    return plan._plan if isinstance(plan, WithLoose) else plan

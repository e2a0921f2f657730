"""Mesh decimation by quadric-error half-edge collapses (Garland & Heckbert 1997), keeping UVs.

A half-edge collapse u -> v deletes u and keeps v where it is, so the decimated mesh's vertices are
a subset of the full mesh's: shape basis, skinning weights and UVs carry over exactly by indexing.
A collapse is only taken when it keeps the surface manifold (link condition), keeps boundaries
(eye and mouth openings) in place, keeps every UV chart intact (each UV corner of u must have a
matching corner of v across a face on the collapsed edge), and flips no triangle in 3D or in UV
space.
"""

import heapq

import numpy as np


def _face_normal(p):
    return np.cross(p[1] - p[0], p[2] - p[0])


def _uv_area(t):
    return (t[1, 0] - t[0, 0]) * (t[2, 1] - t[0, 1]) - (t[2, 0] - t[0, 0]) * (t[1, 1] - t[0, 1])


class Decimator:
    def __init__(self, positions, faces, uv_faces, uvs, spread):
        """`spread` weighs a penalty on edge length (relative to the quadric error) that keeps
        the triangles even, instead of spending the budget on fingers and ears only."""
        self.pos = np.asarray(positions, dtype=np.float64)
        self.faces = np.array(faces, dtype=np.int64)
        self.uvf = np.array(uv_faces, dtype=np.int64)
        self.uvs = np.asarray(uvs, dtype=np.float64)
        nv = len(self.pos)
        self.face_alive = np.ones(len(self.faces), dtype=bool)
        self.vert_alive = np.zeros(nv, dtype=bool)
        self.vert_alive[np.unique(self.faces)] = True
        self.vfaces = [set() for _ in range(nv)]
        for f, tri in enumerate(self.faces):
            for v in tri:
                self.vfaces[v].add(f)
        self.version = np.zeros(nv, dtype=np.int64)
        self.quadric = np.zeros((nv, 4, 4))
        areas = []
        for f, tri in enumerate(self.faces):
            n = _face_normal(self.pos[tri])
            area = np.linalg.norm(n) / 2
            areas.append(area)
            n = n / max(np.linalg.norm(n), 1e-30)
            plane = np.append(n, -n @ self.pos[tri[0]])
            for v in tri:
                self.quadric[v] += area * np.outer(plane, plane)
        mean_area = float(np.mean(areas))
        self.spread = spread * mean_area
        # Boundary edges: a stiff plane through the edge, perpendicular to its face.
        for (a, b), fs in self._edge_faces().items():
            if len(fs) == 1:
                tri = self.faces[fs[0]]
                n = _face_normal(self.pos[tri])
                e = self.pos[b] - self.pos[a]
                m = np.cross(e, n)
                m /= max(np.linalg.norm(m), 1e-30)
                plane = np.append(m, -m @ self.pos[a])
                k = 100.0 * (e @ e) * np.outer(plane, plane)
                self.quadric[a] += k
                self.quadric[b] += k
        self.heap = []
        for (a, b) in self._edge_faces():
            self._push(a, b)
            self._push(b, a)

    def _edge_faces(self):
        edges = {}
        for f in np.nonzero(self.face_alive)[0]:
            tri = self.faces[f]
            for i in range(3):
                a, b = int(tri[i]), int(tri[(i + 1) % 3])
                edges.setdefault((min(a, b), max(a, b)), []).append(f)
        return edges

    def _cost(self, u, v):
        p = np.append(self.pos[v], 1.0)
        d = self.pos[u] - self.pos[v]
        return float(p @ (self.quadric[u] + self.quadric[v]) @ p) + self.spread * float(d @ d)

    def _push(self, u, v):
        heapq.heappush(self.heap, (self._cost(u, v), u, v, self.version[u], self.version[v]))

    def _neighbours(self, v):
        out = set()
        for f in self.vfaces[v]:
            out.update(int(x) for x in self.faces[f])
        out.discard(v)
        return out

    def _is_boundary(self, v):
        count = {}
        for f in self.vfaces[v]:
            for w in self.faces[f]:
                if w != v:
                    count[int(w)] = count.get(int(w), 0) + 1
        return any(c == 1 for c in count.values())

    def _plan(self, u, v):
        """The UV remapping of u's corners for the collapse u -> v, or None if it is not allowed."""
        shared = self.vfaces[u] & self.vfaces[v]
        if not shared or len(shared) > 2:
            return None
        opposite = set()
        for f in shared:
            opposite.update(int(x) for x in self.faces[f] if x != u and x != v)
        if self._neighbours(u) & self._neighbours(v) != opposite:
            return None
        if self._is_boundary(u) and len(shared) != 1:
            return None
        uv_map = {}
        for f in shared:
            tri = list(self.faces[f])
            a, b = self.uvf[f][tri.index(u)], self.uvf[f][tri.index(v)]
            if uv_map.setdefault(a, b) != b:
                return None
        for f in self.vfaces[u] - shared:
            tri = self.faces[f]
            i = list(tri).index(u)
            a = self.uvf[f][i]
            if a not in uv_map:
                return None
            old = self.pos[tri]
            new = old.copy()
            new[i] = self.pos[v]
            n_old, n_new = _face_normal(old), _face_normal(new)
            len_new = np.linalg.norm(n_new)
            if len_new < 1e-12 or n_old @ n_new < 0.3 * np.linalg.norm(n_old) * len_new:
                return None
            t_old = self.uvs[self.uvf[f]]
            t_new = t_old.copy()
            t_new[i] = self.uvs[uv_map[a]]
            if _uv_area(t_old) * _uv_area(t_new) <= 0:
                return None
        return shared, uv_map

    def _collapse(self, u, v, shared, uv_map):
        for f in shared:
            self.face_alive[f] = False
            for w in self.faces[f]:
                self.vfaces[w].discard(f)
        for f in list(self.vfaces[u]):
            i = list(self.faces[f]).index(u)
            self.uvf[f][i] = uv_map[self.uvf[f][i]]
            self.faces[f][i] = v
            self.vfaces[v].add(f)
        self.vfaces[u] = set()
        self.vert_alive[u] = False
        self.quadric[v] += self.quadric[u]
        self.version[v] += 1
        for w in self._neighbours(v):
            self._push(v, w)
            self._push(w, v)

    def run(self, target_vertices):
        alive = int(self.vert_alive.sum())
        while alive > target_vertices and self.heap:
            _, u, v, ver_u, ver_v = heapq.heappop(self.heap)
            if not (self.vert_alive[u] and self.vert_alive[v]):
                continue
            if ver_u != self.version[u] or ver_v != self.version[v]:
                continue
            plan = self._plan(u, v)
            if plan is None:
                continue
            self._collapse(u, v, *plan)
            alive -= 1
        return alive

    def result(self):
        """(kept vertex ids, faces over kept ids, used uv ids, uv faces over used uv ids)."""
        faces = self.faces[self.face_alive]
        uvf = self.uvf[self.face_alive]
        kept = np.unique(faces)
        used_uv = np.unique(uvf)
        return kept, np.searchsorted(kept, faces), used_uv, np.searchsorted(used_uv, uvf)


def euler_characteristic(faces):
    edges = {tuple(sorted((int(t[i]), int(t[(i + 1) % 3])))) for t in faces for i in range(3)}
    return len(np.unique(faces)) - len(edges) + len(faces)


def decimate(positions, faces, uv_faces, uvs, target_vertices, spread=0.05):
    d = Decimator(positions, faces, uv_faces, uvs, spread)
    d.run(target_vertices)
    return d.result()

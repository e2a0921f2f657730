"""The cloth solver's peer: NVIDIA Newton's XPBD solver (Apache-2.0), an implementation nobody here
wrote, on the same grid, material and drop as `crates/mannequin-cloth/tests/newton.rs`.

`fixture DIR`: a 17×17 grid 10 cm apart (Mannequin's triangulation, through `add_cloth_mesh`),
held flat 2 m up, pinned and let go, 10 substeps per 1/60 s frame of one XPBD iteration each
(Mannequin's small steps). Material: 10 kg/m² (masses lumped from triangle areas by both), a
distance constraint of compliance 1e-3 m/N on every mesh edge (Newton springs with
ke = 1 / compliance: its XPBD spring uses alpha = 1 / (ke·dt²), as Mannequin's α/Δt², on the
same C = |xᵢ − xⱼ| − l₀), no bending to speak of (compliance 1e9), and Mannequin's velocity
damping v ← v·e^(−2.4·Δt) applied after each Newton substep (Newton's XPBD has none). No
contacts. Two scenes, one file each in DIR:

- `newton_four_corners.npz`: pinned at its four corners, a hammock, 10 s. Its rest is the
  static equilibrium of the spring network under gravity, which is unique (every edge is in
  tension, nothing can fold), so whole positions are compared. The stretch mapping between the
  two solvers is exact (same constraint, same α), so the sag is no matter of how parameters
  translate. The file also holds `equilibrium`, that rest found directly in float64 by Newton's
  method on Σ ½·ke·(l − l₀)² + Σ m·g·y: one XPBD pass per substep stops short of it (its
  bias shrinks as Δt²), Newton's Jacobi sums more than Mannequin's coloured Gauss–Seidel
  sweep, which bounds how far apart the two may rest.
- `newton_diagonal_hang.npz`: pinned at two diagonally opposite corners, 6 s. A shape set by
  geometry (the centre of mass hangs 70 cm below the pins, about 30 cm of that from stretch),
  but without bending the two hanging halves fold sideways at no cost, differently in each
  solver; the test compares heights only.

Both hold `initial`, `rest` (V×3, float32, in Mannequin's grid order), `faces`, `pins`,
`grid` (nx, ny), `origin` and the scene's numbers (`frames`, `fps`, `substeps`, `spacing`,
`density`, `stretch_compliance`, `bend_compliance`, `damping`, `gravity`).

Why this scale: it is Newton's own cloth example's (10 cm cells, about 0.1 kg per particle,
ke = 1000). Newton's XPBD sums each particle's constraint corrections (Jacobi), and on a cloth
as light and stiff as Mannequin's cotton at 1 cm (1.5e-5 kg per particle, ke = 2000) it blew
up, particles reaching its 1e5 m/s clamp within a second, with or without contacts; with more
substeps the float32 positions stop resolving a substep's fall. Newton's Y axis is up, as
Mannequin's.

`time [--frames N] [--iterations K]`: Newton's ms per 1/60 s frame (10 substeps of K XPBD
iterations, default 10 as its hanging cloth example, whose 10 cm cells, 0.1 kg particles and
ke = 1000 it uses; Mannequin does 1) on 64×32 and 100×100 grids pinned along one edge and let go
horizontally (as `cargo bench -p mannequin-cloth` does on 1 cm grids), with particle
self-collision (spheres of radius half the spacing, as Mannequin's 5 mm thickness at 1 cm) and
without (radius 0, no particle hash grid). The first frame (Warp compiling its kernels) is not
timed. Prints one JSON object on its last line:
`{"64x32": {"plain": ms, "self_collision": ms}, "100x100": {...}}`.

Run: $HOME/.cache/mannequin-newton/bin/python tools/oracles/cloth_newton.py fixture crates/mannequin-cloth/tests/fixtures
(the venv: python3 -m venv ~/.cache/mannequin-newton && ~/.cache/mannequin-newton/bin/pip install newton==1.8.0;
CPU only, no GPU needed)
"""
import json
import os
import sys
import time

import numpy as np
import warp as wp

import newton

DENSITY = 10.0
STRETCH_COMPLIANCE = 1e-3
BEND_COMPLIANCE = 1e9
FRICTION = 0.5
DAMPING = 2.4
GRAVITY = -9.81
N, SPACING, ORIGIN = 17, 0.1, (-0.8, 2.0, -0.8)
SCENES = {
    # name: (pinned grid vertices, frames at 60 per second)
    "four_corners": ([0, N - 1, N * N - N, N * N - 1], 600),
    "diagonal_hang": ([0, N * N - 1], 360),
}


def grid(nx, ny, spacing, origin):
    """Mannequin's test grid: vertex (i, j) at origin + (i, 0, j)·spacing, each cell split along
    the diagonal from (i, j) to (i+1, j+1)."""
    vertices = [(origin[0] + i * spacing, origin[1], origin[2] + j * spacing) for j in range(ny) for i in range(nx)]
    faces = []
    for j in range(ny - 1):
        for i in range(nx - 1):
            a, b, c, d = j * nx + i, j * nx + i + 1, (j + 1) * nx + i + 1, (j + 1) * nx + i
            faces += [(a, b, c), (a, c, d)]
    return vertices, faces


def mesh_edges(faces):
    return sorted({tuple(sorted((f[k], f[(k + 1) % 3]))) for f in faces for k in range(3)})


def build(vertices, faces, radius, pinned=()):
    builder = newton.ModelBuilder(up_axis=newton.Axis.Y, gravity=(0.0, GRAVITY, 0.0))
    builder.add_cloth_mesh(
        pos=wp.vec3(0.0, 0.0, 0.0),
        rot=wp.quat_identity(),
        scale=1.0,
        vel=wp.vec3(0.0, 0.0, 0.0),
        vertices=[wp.vec3(*v) for v in vertices],
        indices=[i for f in faces for i in f],
        density=DENSITY,
        edge_ke=1.0 / BEND_COMPLIANCE,
        edge_kd=0.0,
        particle_radius=radius,
    )
    # Distance constraints on the mesh edges only, as Mannequin's stretch (Newton's add_springs
    # would also tie each edge's opposite vertices, a bending stiffness Mannequin does not have).
    for i, j in mesh_edges(faces):
        builder.add_spring(i, j, 1.0 / STRETCH_COMPLIANCE, 0.0, control=0.0)
    for p in pinned:
        builder.particle_mass[p] = 0.0
        builder.particle_flags[p] = builder.particle_flags[p] & ~int(newton.ParticleFlags.ACTIVE)
    model = builder.finalize(device="cpu")
    model.particle_mu = FRICTION
    if radius == 0.0:
        # The solver rebuilds this hash grid every substep whenever it exists, even with no
        # particle radius to collide with.
        model.particle_grid = None
    return model


class Run:
    """Newton's XPBD stepping a model with no shapes: no collision pipeline, contacts None (the
    solver still handles particle-particle contact when particles have a radius)."""

    def __init__(self, model, substeps, iterations, damping=0.0):
        self.model, self.substeps, self.damping = model, substeps, damping
        self.solver = newton.solvers.SolverXPBD(model, iterations=iterations)
        self.state_0, self.state_1 = model.state(), model.state()
        self.control = model.control()

    def frame(self, dt):
        for _ in range(self.substeps):
            self.state_0.clear_forces()
            self.solver.step(self.state_0, self.state_1, self.control, None, dt / self.substeps)
            self.state_0, self.state_1 = self.state_1, self.state_0
            if self.damping > 0.0:
                keep = np.exp(-self.damping * dt / self.substeps)
                self.state_0.particle_qd.assign(self.state_0.particle_qd.numpy() * keep)

    def positions(self):
        return self.state_0.particle_q.numpy().copy()

    def speed(self):
        return float(np.linalg.norm(self.state_0.particle_qd.numpy(), axis=1).max())


def lumped_masses(vertices, faces):
    x = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces)
    area = 0.5 * np.linalg.norm(np.cross(x[f[:, 1]] - x[f[:, 0]], x[f[:, 2]] - x[f[:, 0]]), axis=1)
    mass = np.zeros(len(x))
    np.add.at(mass, f.ravel(), np.repeat(area * DENSITY / 3.0, 3))
    return mass


def static_equilibrium(vertices, faces, pins, start):
    """The minimum of Σ ½·k·(l − l₀)² + Σ m·g·y over the free particles, in float64, by Newton's
    method from `start` with a backtracking line search (the Hessian's compressive part is
    dropped, so each step goes downhill)."""
    rest = np.asarray(vertices, dtype=np.float64)
    edges = np.asarray(mesh_edges(faces))
    i, j = edges[:, 0], edges[:, 1]
    l0 = np.linalg.norm(rest[i] - rest[j], axis=1)
    k, mass = 1.0 / STRETCH_COMPLIANCE, lumped_masses(vertices, faces)
    free = np.ones(len(rest), bool)
    free[list(pins)] = False
    dofs = np.repeat(free, 3)

    def energy(x):
        length = np.linalg.norm(x[i] - x[j], axis=1)
        return 0.5 * k * ((length - l0) ** 2).sum() - GRAVITY * (mass * x[:, 1]).sum()

    x = np.asarray(start, dtype=np.float64).copy()
    for _ in range(200):
        d = x[i] - x[j]
        length = np.linalg.norm(d, axis=1)
        n = d / length[:, None]
        grad = np.zeros_like(x)
        grad[:, 1] -= GRAVITY * mass
        force = (k * (length - l0))[:, None] * n
        np.add.at(grad, i, force)
        np.add.at(grad, j, -force)
        g = grad.ravel()[dofs]
        if np.abs(g).max() < 1e-6:  # N; with edges 1000 N/m stiff, nanometres from the minimum
            break
        t = np.maximum(1.0 - l0 / length, 0.0)
        block = k * (t[:, None, None] * np.eye(3) + (1.0 - t)[:, None, None] * n[:, :, None] * n[:, None, :])
        hessian = np.zeros((x.size, x.size))
        for a, b, sign in ((i, i, 1.0), (j, j, 1.0), (i, j, -1.0), (j, i, -1.0)):
            rows = (3 * a[:, None, None] + np.arange(3)[None, :, None]).repeat(3, 2)
            cols = (3 * b[:, None, None] + np.arange(3)[None, None, :]).repeat(3, 1)
            np.add.at(hessian, (rows, cols), sign * block)
        step = np.zeros(x.size)
        step[dofs] = np.linalg.solve(hessian[np.ix_(dofs, dofs)], -g)
        step = step.reshape(-1, 3)
        e0, s = energy(x), 1.0
        while energy(x + s * step) > e0 and s > 1e-8:
            s *= 0.5
        x += s * step
    else:
        raise RuntimeError("Newton's method did not converge")
    return x


def distances(a, b):
    d = np.linalg.norm(np.asarray(a, np.float64) - np.asarray(b, np.float64), axis=1)
    return d.max(), np.sqrt((d**2).mean())


def fixture(out_dir):
    vertices, faces = grid(N, N, SPACING, ORIGIN)
    os.makedirs(out_dir, exist_ok=True)
    for name, (pins, frames) in SCENES.items():
        run = Run(build(vertices, faces, 0.0, pinned=pins), substeps=10, iterations=1, damping=DAMPING)
        dt = 1.0 / 60.0
        initial = run.positions()
        for _ in range(frames):
            run.frame(dt)
        rest = run.positions()
        extra = {}
        if name == "four_corners":
            extra["equilibrium"] = static_equilibrium(vertices, faces, pins, rest)
        path = os.path.join(out_dir, f"newton_{name}.npz")
        np.savez_compressed(
            path,
            initial=initial.astype(np.float32),
            rest=rest.astype(np.float32),
            faces=np.asarray(faces, dtype=np.int64),
            pins=np.asarray(pins, dtype=np.int64),
            grid=np.array([N, N], dtype=np.int64),
            origin=np.array(ORIGIN),
            frames=np.array([frames], dtype=np.int64),
            fps=np.array([60.0]),
            substeps=np.array([10], dtype=np.int64),
            spacing=np.array([SPACING]),
            density=np.array([DENSITY]),
            stretch_compliance=np.array([STRETCH_COMPLIANCE]),
            bend_compliance=np.array([BEND_COMPLIANCE]),
            damping=np.array([DAMPING]),
            gravity=np.array([GRAVITY]),
            **extra,
        )
        print(f"wrote {path} ({os.path.getsize(path)} bytes): lowest particle at y = {rest[:, 1].min():.4f}, "
              f"largest speed at the end {run.speed():.5f} m/s")
        if "equilibrium" in extra:
            worst, rms = distances(rest, extra["equilibrium"])
            print(f"  Newton's rest from the static equilibrium: worst {worst:.4f} m, RMS {rms:.4f} m")


def time_grids(frames, iterations):
    result = {}
    for nx, ny in [(64, 32), (100, 100)]:
        vertices, faces = grid(nx, ny, 0.1, (0.0, 4.0, 0.0))
        result[f"{nx}x{ny}"] = {}
        for case, radius in [("plain", 0.0), ("self_collision", 0.05)]:
            run = Run(build(vertices, faces, radius, pinned=range(nx)), substeps=10, iterations=iterations)
            run.frame(1.0 / 60.0)  # warm-up: Warp compiles its kernels on first use
            start = time.perf_counter()
            for _ in range(frames):
                run.frame(1.0 / 60.0)
            result[f"{nx}x{ny}"][case] = (time.perf_counter() - start) * 1e3 / frames
    print(json.dumps(result))


def option(name, default):
    return int(sys.argv[sys.argv.index(name) + 1]) if name in sys.argv else default


def main():
    wp.config.quiet = True
    wp.init()
    if len(sys.argv) >= 3 and sys.argv[1] == "fixture":
        fixture(sys.argv[2])
    elif len(sys.argv) >= 2 and sys.argv[1] == "time":
        time_grids(option("--frames", 60), option("--iterations", 10))
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()

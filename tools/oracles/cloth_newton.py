"""The cloth solver's peer: NVIDIA Newton's XPBD solver (Apache-2.0), an implementation nobody here
wrote, on the same grid, material and drop as `crates/mannequin-cloth/tests/newton.rs`.

`fixture DIR`: a 17×17 grid 10 cm apart (Mannequin's triangulation, through `add_cloth_mesh`),
held flat 2 m up and pinned at two diagonally opposite corners, let go: 6 s at 60 frames per
second, 10 substeps of one XPBD iteration each (Mannequin's small steps). Material: 10 kg/m²
(masses lumped from triangle areas by both), a distance constraint of compliance 1e-3 m/N on
every mesh edge (Newton springs with ke = 1 / compliance: its XPBD spring uses
alpha = 1 / (ke·dt²)), no bending to speak of (compliance 1e9), and Mannequin's velocity damping
v ← v·e^(−2.4·Δt) applied after each Newton substep (Newton's XPBD has none). No contacts.

Why this scene: its resting shape is the static equilibrium of a spring network under gravity,
which both solvers reach whatever their path (XPBD's fixed point is the compliant equilibrium),
so the two should agree to within what is left of the motion. The scale is Newton's own cloth
example's (10 cm cells, about 0.1 kg per particle, ke = 1000): Newton's XPBD sums each
particle's constraint corrections (Jacobi), and on a cloth as light and stiff as Mannequin's
cotton at 1 cm (1.5e-5 kg per particle, ke = 2000) it blew up, particles reaching its 1e5 m/s
clamp within a second, with or without contacts; with more substeps the float32 positions stop
resolving a substep's fall. Newton's Y axis is up, as Mannequin's. Writes
DIR/newton_diagonal_hang.npz: `initial` and `rest` positions (V×3, float32, in Mannequin's grid
order), `faces`, `pins` and the scenario's numbers.

`time [--frames N]`: Newton's ms per 1/60 s frame (10 substeps × 10 iterations, as its hanging
cloth example, whose 10 cm cells, 0.1 kg particles and ke = 1000 it uses) on 64×32 and 100×100
grids pinned along one edge and let go horizontally (as `cargo bench -p mannequin-cloth` does on
1 cm grids), with particle self-collision (radius half the spacing, as Mannequin's 5 mm
thickness at 1 cm) and without (radius 0). Prints one JSON object.

Run: $HOME/.cache/mannequin-newton/bin/python tools/oracles/cloth_newton.py fixture crates/mannequin-cloth/tests/fixtures
(the venv: python3 -m venv ~/.cache/mannequin-newton && ~/.cache/mannequin-newton/bin/pip install newton==1.8.0)
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


DAMPING = 2.4


def build(vertices, faces, radius, pinned=()):
    builder = newton.ModelBuilder(up_axis=newton.Axis.Y)
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
    edges = {tuple(sorted((f[k], f[(k + 1) % 3]))) for f in faces for k in range(3)}
    for i, j in sorted(edges):
        builder.add_spring(i, j, 1.0 / STRETCH_COMPLIANCE, 0.0, control=0.0)
    for p in pinned:
        builder.particle_mass[p] = 0.0
        builder.particle_flags[p] = builder.particle_flags[p] & ~int(newton.ParticleFlags.ACTIVE)
    model = builder.finalize(device="cpu")
    model.soft_contact_mu = FRICTION
    model.particle_mu = FRICTION
    return model


class Run:
    def __init__(self, model, substeps, iterations, damping=0.0):
        self.model, self.substeps, self.damping = model, substeps, damping
        self.solver = newton.solvers.SolverXPBD(model, iterations=iterations)
        self.state_0, self.state_1 = model.state(), model.state()
        self.control = model.control()
        self.pipeline = newton.CollisionPipeline(model)
        self.contacts = self.pipeline.contacts()

    def frame(self, dt):
        for _ in range(self.substeps):
            self.state_0.clear_forces()
            self.pipeline.collide(self.state_0, self.contacts)
            self.solver.step(self.state_0, self.state_1, self.control, self.contacts, dt / self.substeps)
            self.state_0, self.state_1 = self.state_1, self.state_0
            if self.damping > 0.0:
                keep = np.exp(-self.damping * dt / self.substeps)
                self.state_0.particle_qd.assign(self.state_0.particle_qd.numpy() * keep)

    def positions(self):
        return self.state_0.particle_q.numpy().copy()

    def speed(self):
        return float(np.linalg.norm(self.state_0.particle_qd.numpy(), axis=1).max())


def fixture(out_dir):
    n, spacing = 17, 0.1
    vertices, faces = grid(n, n, spacing, (-0.8, 2.0, -0.8))
    pins = [0, n * n - 1]
    run = Run(build(vertices, faces, 0.0, pinned=pins), substeps=10, iterations=1, damping=DAMPING)
    frames, dt = 360, 1.0 / 60.0
    initial = run.positions()
    for _ in range(frames):
        run.frame(dt)
    rest = run.positions()
    os.makedirs(out_dir, exist_ok=True)
    path = os.path.join(out_dir, "newton_diagonal_hang.npz")
    np.savez_compressed(
        path,
        initial=initial.astype(np.float32),
        rest=rest.astype(np.float32),
        faces=np.asarray(faces, dtype=np.int64),
        pins=np.asarray(pins, dtype=np.int64),
        frames=np.array([frames], dtype=np.int64),
        fps=np.array([60.0]),
        substeps=np.array([10], dtype=np.int64),
        spacing=np.array([spacing]),
        density=np.array([DENSITY]),
        stretch_compliance=np.array([STRETCH_COMPLIANCE]),
        bend_compliance=np.array([BEND_COMPLIANCE]),
        damping=np.array([DAMPING]),
    )
    low = rest[:, 1].min()
    print(f"wrote {path}: lowest particle at y = {low:.4f}, largest speed at the end {run.speed():.5f} m/s")


def time_grids(frames):
    result = {}
    for nx, ny in [(64, 32), (100, 100)]:
        vertices, faces = grid(nx, ny, 0.1, (0.0, 4.0, 0.0))
        result[f"{nx}x{ny}"] = {}
        for case, radius in [("plain", 0.0), ("self_collision", 0.05)]:
            run = Run(build(vertices, faces, radius, pinned=range(nx)), substeps=10, iterations=10)
            run.frame(1.0 / 60.0)  # warm-up: Warp compiles its kernels on first use
            start = time.perf_counter()
            for _ in range(frames):
                run.frame(1.0 / 60.0)
            result[f"{nx}x{ny}"][case] = (time.perf_counter() - start) * 1e3 / frames
    print(json.dumps(result))


def main():
    wp.config.quiet = True
    wp.init()
    if len(sys.argv) >= 3 and sys.argv[1] == "fixture":
        fixture(sys.argv[2])
    elif len(sys.argv) >= 2 and sys.argv[1] == "time":
        frames = int(sys.argv[sys.argv.index("--frames") + 1]) if "--frames" in sys.argv else 60
        time_grids(frames)
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()

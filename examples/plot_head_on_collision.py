"""
Two spheres colliding: a scene built by hand
============================================

The smallest :class:`pendular.Simulation`: two spheres in a box, the linear contact law, no
damping. A scene declares its step pipeline in one call — the neighbour list, the forces, the
controls, the integrator and the writers — and ``sim.run(steps)`` advances it. A writer is any
object with ``apply(sim)``; here one records the overlap of the pair every step.

Against the closed form: an undamped linear spring of stiffness k_n = E R (equal spheres) holds
two spheres of reduced mass m/2 in contact for π √(m / (2 k_n)), and gives them back their
approach speed (restitution 1).
"""

import matplotlib.pyplot as plt
import numpy as np

from pendular import ContactForces, Integrator, NeighborList, Particles, Simulation, WallForces, Walls
from pendular.dem.contact_law import normal_stiffness

radius, young, density, speed = 1e-3, 1e6, 2650.0, 0.01       # m, Pa, kg/m^3, m/s
particles = Particles(np.array([[-1.001 * radius, 0, 0], [1.001 * radius, 0, 0]]),
                      np.array([radius, radius]), density,
                      velocity=np.array([[speed, 0, 0], [-speed, 0, 0]]))
walls = Walls.box([-0.01] * 3, [0.01] * 3)                     # far out of reach
stiffness = normal_stiffness(young, radius, radius)           # E R [N/m]
dt = 0.01 * np.sqrt(particles.mass[0] / stiffness)            # [s]


class OverlapRecorder:
    """A writer: the time [s] and the overlap [m] of the first pair, every step."""

    def __init__(self):
        self.rows = []

    def apply(self, sim):
        overlap = sim.contacts.overlap[0] if len(sim.contacts.overlap) else 0.0
        self.rows.append((sim.time, max(overlap, 0.0)))


recorder = OverlapRecorder()
sim = Simulation(particles, walls, dt,
                 neighbors=NeighborList(0.2 * radius),
                 forces=[ContactForces(young, shear_ratio=0.3, friction_deg=18.0),
                         WallForces(young)],
                 integrator=Integrator(damping=0.0),
                 writers=[recorder])
expected = np.pi * np.sqrt(0.5 * particles.mass[0] / stiffness)
sim.run(int(3 * expected / dt))

time, overlap = np.array(recorder.rows).T
duration = np.count_nonzero(overlap > 0) * dt
rebound = sim.particles.velocity[1, 0] - sim.particles.velocity[0, 0]
print(f"contact duration {duration:.4e} s, closed form {expected:.4e} s "
      f"({duration / expected - 1:+.2%})")
print(f"relative speed after {rebound:.6f} m/s, before {2 * speed:.6f} m/s")

# %%
# The overlap follows half a sine of the spring's period:

figure, axes = plt.subplots(figsize=(6, 3.5))
axes.plot(1e6 * time, 1e9 * overlap, label="pendular")
start = time[np.argmax(overlap > 0)]
closed = np.linspace(0, expected, 200)
axes.plot(1e6 * (start + closed),
          1e9 * speed / (np.pi / expected) * np.sin(np.pi * closed / expected), "--",
          label="closed form")
axes.set_xlabel("time [µs]")
axes.set_ylabel("overlap [nm]")
axes.set_title("head-on collision, E = 1 MPa, R = 1 mm, v = ±1 cm/s")
axes.legend()
figure.tight_layout()
plt.show()

"""Grips: particles that move rigidly with a wall (a control of the engine; direct tension,
pendular.procedures.tension, grips its sample at the z walls; the GPU runs the same control,
pendular.gpu.grips).

A wall only pushes, so a test that pulls holds the sample by its ends: the particles ``members``
move rigidly with wall ``wall`` (a prescribed velocity, no rotation), as a sample glued to a
rough platen. The force the rig needs to hold a grip on its path is minus the resultant on its
particles; without the wall's own push on them (the wall and its grip are one rigid body) that
is the force of the specimen on the grip, ``Grip.pull`` [N], positive when the specimen pulls
the grip inward (tension).
"""

import numpy as np


class Grip:
    """Particles ``members`` moving rigidly with wall ``wall`` (0..5): each step their force
    and torque are replaced by the prescribed motion (velocity = the wall's, along its axis;
    no spin). A control: it runs after the force operations and after the wall controls that
    move its wall, before the Integrator.

    ``pull`` [N]: force of the rest of the sample on the grip along the wall's axis, positive
    toward the sample (tension); the wall's push on the members (``walls.force[wall]``) is not
    part of it: all particles touching the wall must be members
    (pendular.procedures.grips.grip_members). On a device the pull comes back with the walls
    (reading ``sim.walls``), the particles left there.
    """

    def __init__(self, wall, members):
        if wall not in range(6):
            raise ValueError(f"wall = {wall!r} is outside the valid range 0..5")
        self.wall = wall
        self.axis = wall // 2
        self.inward = 1.0 if wall % 2 == 0 else -1.0   # unit direction from the wall into the box
        self.members = np.asarray(members, np.int64)
        if len(self.members) == 0:
            raise ValueError(f"grip of wall {wall} has no particles: increase the grip depth")
        self.pull = 0.0

    def state_dict(self):
        """``pull`` [N], that of the last step (the members are the scene's: chosen from the
        state the pull starts from)."""
        return {"pull": self.pull}

    def load_state(self, state):
        pull = float(state["pull"])
        if not np.isfinite(pull):
            raise ValueError(f"pull = {pull!r} N is not finite")
        self.pull = pull

    def apply(self, sim):
        p = sim.particles
        resultant = float(np.sum(p.force[self.members, self.axis]))
        self.pull = self.inward * resultant - sim.walls.force[self.wall]
        p.force[self.members] = 0.0
        p.torque[self.members] = 0.0
        p.angular_velocity[self.members] = 0.0
        p.velocity[self.members] = 0.0
        p.velocity[self.members, self.axis] = -self.inward * sim.walls.velocity[self.wall]

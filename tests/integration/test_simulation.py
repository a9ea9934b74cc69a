"""The step pipeline of pendular.dem.simulation.Simulation: order of a step, the read-only list of
operations, lookup by type, and scene changes through the public lists."""

import numpy as np
import pytest

from conftest import RADIUS, YOUNG, two_body_scene
from pendular.dem.contact_law import ContactForces
from pendular.dem.integrate import Integrator
from pendular.dem.neighbors import NeighborList
from pendular.dem.record import HistoryRecorder
from pendular.dem.simulation import Simulation, StaleState
from pendular.dem.state import Particles, Walls
from pendular.dem.walls import StressServo, WallForces


class Logged:
    """Test operation: note (name, step, time, whether any force is set) in ``journal``, then
    run ``inner`` if given."""

    def __init__(self, name, journal, inner=None):
        self.name = name
        self.journal = journal
        self.inner = inner

    def apply(self, sim):
        self.journal.append((self.name, sim.step, sim.time, bool(sim.particles.force.any())))
        if self.inner is not None:
            self.inner.apply(sim)


def logged_scene(journal):
    """Two overlapping spheres (a contact force every step), every operation logged."""
    particles = Particles(np.array([[0.0, 0, 0], [1.9 * RADIUS, 0, 0]]), np.full(2, RADIUS),
                          2650.0)
    return Simulation(particles, Walls.box([-1.0] * 3, [1.0] * 3), 1e-6,
                      neighbors=Logged("neighbors", journal, NeighborList(0.2 * RADIUS)),
                      forces=[Logged("contacts", journal, ContactForces(YOUNG)),
                              Logged("walls", journal, WallForces(YOUNG))],
                      controls=[Logged("servo", journal), Logged("growth", journal)],
                      integrator=Logged("integrator", journal, Integrator(0.0)),
                      writers=[Logged("writer", journal)])


def test_a_step_runs_the_declared_pipeline_in_order():
    """Forces zeroed, neighbour list, forces, controls, integrator; then step and time advance
    and the writers see the new state."""
    journal = []
    sim = logged_scene(journal)
    sim.run(2)
    expected = []
    for step in range(2):
        time = step * sim.dt
        expected += [("neighbors", step, time, False), ("contacts", step, time, False),
                     ("walls", step, time, True), ("servo", step, time, True),
                     ("growth", step, time, True), ("integrator", step, time, True),
                     ("writer", step + 1, time + sim.dt, True)]
    assert journal == expected


def test_operations_are_read_only_and_follow_the_public_lists():
    sim = two_body_scene([[0, 0, 0], [1.9 * RADIUS, 0, 0]], np.zeros((2, 3)))
    assert sim.operations == (sim.neighbors, *sim.forces, sim.integrator)
    with pytest.raises(AttributeError):
        sim.operations = ()
    with pytest.raises(TypeError):
        sim.operations[0] = NeighborList(1.0)
    servo = StressServo("xyz", 1.0, 1.0)
    sim.controls = [servo]
    assert sim.operations[-2] is servo
    assert sim.operation(StressServo) is servo
    assert sim.operation(WallForces) is sim.forces[1]
    recorder = HistoryRecorder(1, {"step": lambda s: s.step})
    sim.writers.append(recorder)
    assert sim.operation(HistoryRecorder) is recorder
    sim.controls = []
    with pytest.raises(KeyError, match="StressServo"):
        sim.operation(StressServo)


def test_an_appended_force_acts_from_the_next_step():
    class Push:
        def apply(self, sim):
            sim.particles.force[0, 0] += 1e-9

    sim = two_body_scene([[0.0, 0, 0]], np.zeros((1, 3)))
    sim.advance()
    assert not sim.particles.velocity.any()
    sim.forces.append(Push())
    sim.advance()
    assert sim.particles.velocity[0, 0] > 0.0


def test_a_recorder_counts_its_periods_from_its_origin():
    """A shear that starts at step 7 with period 3 records at 7, 10, 13: its last record falls
    on its last step whatever step the preparation ended at."""
    sim = two_body_scene([[0.0, 0, 0]], np.zeros((1, 3)))
    sim.run(7)
    recorder = HistoryRecorder(3, {"step": lambda s: s.step}, origin=sim.step)
    recorder.record(sim)
    sim.writers.append(recorder)
    sim.run(6)
    assert recorder.arrays()["step"].tolist() == [7, 10, 13]


def test_a_recorder_records_the_end_of_a_phase_between_periods():
    sim = two_body_scene([[0.0, 0, 0]], np.zeros((1, 3)))
    recorder = HistoryRecorder(4, {"step": lambda s: s.step}, end=10)
    sim.writers.append(recorder)
    sim.run(12)
    assert recorder.arrays()["step"].tolist() == [4, 8, 10, 12]


def test_an_interrupt_during_a_record_leaves_whole_rows_only():
    """Ctrl-C while a record is computed (the CI failure: 'anisotropy' one record short of the
    other columns) leaves no partial row; a row cut short while appending is not counted."""
    sim = two_body_scene([[0.0, 0, 0]], np.zeros((1, 3)))

    def interrupted(s):
        if s.step == 2:
            raise KeyboardInterrupt
        return 2.0 * s.step

    recorder = HistoryRecorder(1, {"step": lambda s: s.step, "twice": interrupted})
    sim.writers.append(recorder)
    with pytest.raises(KeyboardInterrupt):
        sim.run(5)
    columns = recorder.arrays()
    assert columns["step"].tolist() == [1] and columns["twice"].tolist() == [2.0]
    recorder.rows["step"].append(np.float64(3.0))        # an append cut short
    assert len(recorder) == 1 and recorder.arrays()["step"].tolist() == [1]


def test_the_run_loop_checks_after_each_chunk_then_until():
    """Simulation.run_chunks (the loop of every device's run): ``advance`` step by step in
    chunks of check_every, after each chunk ``check`` and then ``until``; it stops at the
    first chunk whose until holds, or at the step limit (a short last chunk)."""
    sim = two_body_scene([[0.0, 0, 0]], np.zeros((1, 3)))
    journal = []

    def advance():
        sim.step += 1
        journal.append(("step", sim.step))

    def check():
        journal.append(("check", sim.step))

    def until(s):
        journal.append(("until", s.step))
        return s.step >= 6

    assert sim.run_chunks(10, advance, check=check, until=until, check_every=3) == 6
    assert journal == [("step", 1), ("step", 2), ("step", 3), ("check", 3), ("until", 3),
                       ("step", 4), ("step", 5), ("step", 6), ("check", 6), ("until", 6)]
    journal.clear()
    assert sim.run_chunks(4, advance, check=check, check_every=3) == 4
    assert [entry for entry in journal if entry[0] == "check"] == [("check", 9), ("check", 10)]


def test_a_check_that_raises_stops_the_run():
    sim = two_body_scene([[0.0, 0, 0]], np.zeros((1, 3)))

    def check():
        if sim.step >= 4:
            raise RuntimeError("the device's flags")

    with pytest.raises(RuntimeError, match="device's flags"):
        sim.run_chunks(10, sim.advance, check=check, check_every=2)
    assert sim.step == 4


def test_peek_reads_the_scene_without_bringing_a_device_run_state_back():
    """While a device run holds the state, ``peek`` gives the host's objects (what the scene
    is made of) and copies nothing; ``fetch`` brings the state back: the walls alone, then
    the rest, which ends the hold."""
    sim = two_body_scene([[0.0, 0, 0]], np.zeros((1, 3)))
    walls, controls = sim.walls, sim.controls

    class Device:
        copies = []

        def copy_back(self, part):
            self.copies.append(part)

    sim.hold(Device())
    assert sim.peek("walls") is walls and sim.peek("controls") is controls
    assert Device.copies == []
    assert sim.fetch("walls") is sim and sim.walls is walls and Device.copies == ["walls"]
    sim.fetch("walls")                  # fetched already: no second copy
    assert sim.peek("controls") is controls and Device.copies == ["walls"]
    sim.fetch("controls")
    assert sim.controls is controls and Device.copies == ["walls", None]
    sim.fetch()                         # the host holds it all: nothing to copy
    assert Device.copies == ["walls", None]


def test_reading_held_state_without_fetching_it_is_refused():
    """A read of what a device run holds, not fetched, raises StaleState naming the call that
    brings it back (never a stale host copy); after a fetch of the walls alone, the particles
    are still the device's. On the host, fetch costs nothing and reads as before."""
    sim = two_body_scene([[0.0, 0, 0]], np.zeros((1, 3)))
    assert sim.fetch() is sim and sim.fetch("walls", "particles") is sim

    class Device:
        def copy_back(self, part):
            pass

    sim.hold(Device())
    for name in ("particles", "walls", "contacts", "controls"):
        with pytest.raises(StaleState, match=rf"sim\.fetch\('{name}'\)"):
            getattr(sim, name)
    sim.fetch("walls")
    sim.walls.stress()
    with pytest.raises(StaleState, match="particles"):
        sim.particles.position
    with pytest.raises(ValueError, match="cannot fetch 'forces'"):
        sim.fetch("forces")
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        sim.nothing

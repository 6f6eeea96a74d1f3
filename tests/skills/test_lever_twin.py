"""The lever end to end in the twin: found by its raised marker, pressed down and lifted back by the primitives,
felt held by its latch through the F/T sensor, and read moved from its marker's tilt."""

from world_fixtures import twin_world

from puzzlebox.learning import DualAgent, run_episode
from puzzlebox.models.generator import generate_chain
from puzzlebox.twin.session import TwinSession


def test_a_box_where_a_slide_locks_a_lever_is_solved_with_sensed_outcomes_matching_the_truth():
    spec = generate_chain(["slide", "lever", "door"], seed=1)
    with TwinSession(spec, seed=0) as session:
        world = twin_world(session, seed=2)
        result = run_episode(DualAgent(), world, spec.name, 2, max_actions=10)
        assert result.solved
        assert all(entry.moved == entry.true_moved for entry in world.log)
        levers = [entry for entry in world.log if entry.kind == "lever"]
        assert any(entry.moved for entry in levers)


def test_a_free_lever_is_pressed_down_and_lifted_back_up():
    spec = generate_chain(["lever", "wheel"], seed=4)
    lever = spec.index_of("lever-0")
    with TwinSession(spec, seed=0) as session:
        world = twin_world(session)
        index = next(i for i, m in enumerate(world.markers) if m == spec.components[lever].marker)
        opened = world.try_toggle(index)
        assert opened.moved and session.component_states()[lever] == 1
        closed = world.try_toggle(index)
        assert closed.moved and session.component_states()[lever] == 0
        assert [entry.true_moved for entry in world.log] == [True, True]

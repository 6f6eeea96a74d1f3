"""The drawer end to end in the twin: found by its marker, pulled out and pushed back by the primitives, felt
held by its latch through the F/T sensor, and read moved from its marker leaving its closed pose."""

from world_fixtures import twin_world

from puzzlebox.learning import DualAgent, run_episode
from puzzlebox.models.generator import generate_chain
from puzzlebox.twin.session import TwinSession


def test_a_box_where_a_wheel_locks_a_drawer_is_solved_with_sensed_outcomes_matching_the_truth():
    spec = generate_chain(["wheel", "drawer", "lever"], seed=1)
    with TwinSession(spec, seed=0) as session:
        world = twin_world(session, seed=2)
        result = run_episode(DualAgent(), world, spec.name, 2, max_actions=10)
        assert result.solved
        assert all(entry.moved == entry.true_moved for entry in world.log)
        assert any(entry.moved for entry in world.log if entry.kind == "drawer")


def test_a_free_drawer_is_pulled_out_and_pushed_back_in():
    spec = generate_chain(["drawer", "door"], seed=4)
    drawer = spec.index_of("drawer-0")
    with TwinSession(spec, seed=0) as session:
        world = twin_world(session)
        index = next(i for i, m in enumerate(world.markers) if m == spec.components[drawer].marker)
        assert world.try_toggle(index).moved and session.component_states()[drawer] == 1
        assert world.try_toggle(index).moved and session.component_states()[drawer] == 0
        assert [entry.true_moved for entry in world.log] == [True, True]

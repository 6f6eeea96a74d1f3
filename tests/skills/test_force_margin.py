"""The force margin (issue 36): no try puts more than 45 N of true force on the wrist (the guard stops at 60 N).

A lock's pins leave play: a part held open closes up to ~30 % of its travel before they meet. Closed into them at
the pace of a free part, a slide was driven on to the 60 N guard (63 N true) and left part-way, where the next try
descended onto its post (65 N); a stall past the breakaway is now read as a hold, and the handle taken back."""

from world_fixtures import TrueForceWatch

from puzzlebox.lab.twin_trial import evaluation_world
from puzzlebox.models.generator import generate_chain
from puzzlebox.skills.primitives import HELD_PART_WAY
from puzzlebox.twin.session import TwinSession

FORCE_MARGIN = 45.0
"""Largest true wrist force a try may put on the wrist [N]."""


def test_a_part_held_open_by_a_lock_with_play_reads_blocked_within_the_margin_and_is_taken_back():
    spec = generate_chain(["slide", "wheel"], seed=1)  # open, wheel-1 keeps slide-0 open
    with TwinSession(spec, seed=0) as session:
        robot = TrueForceWatch(session.robot, session)
        world = evaluation_world(session, robot)
        slide, wheel = (world.markers.index(c.marker) for c in spec.components)
        assert world.try_toggle(slide).moved and world.try_toggle(wheel).moved
        robot.peak = 0.0
        held = world.try_toggle(slide)  # closing it: held open by the wheel
        assert held.outcome == "blocked" and held.reason.startswith(HELD_PART_WAY), held
        assert robot.peak <= FORCE_MARGIN, robot.peak_during
        assert session.component_states()[0] == 1 and world.log[-1].progress > 0.1  # taken back where it was
        # and tried again, the handle is where the fingers descend
        again = world.try_toggle(slide)
        assert again.outcome == "blocked" and robot.peak <= FORCE_MARGIN, robot.peak_during

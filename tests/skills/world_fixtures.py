"""A ``TwinWorld`` over a twin session as the trial script wires it (nominal calibration, the spec's goal,
ground truth for scoring only), shared by the skills tests."""

from __future__ import annotations

from skills.twin_world import TwinWorld
from twin.nominal_calibration import nominal_calibration
from twin.session import TwinSession


def twin_world(session: TwinSession, seed: int = 0) -> TwinWorld:
    spec = session.spec
    by_marker = {c.marker: i for i, c in enumerate(spec.components)}
    return TwinWorld(
        session.robot,
        nominal_calibration(session),
        {c.marker: c.kind for c in spec.components},
        spec.components[spec.index_of(spec.goal.component)].marker,
        goal_state=spec.goal.state,
        seed=seed,
        ground_truth=lambda m: int(session.component_states()[by_marker[m]]),
        names={c.marker: c.name for c in spec.components},
    )

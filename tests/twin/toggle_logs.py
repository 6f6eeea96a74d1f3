"""Logged toggles of a twin session, made the way ``experiment.py sysid`` makes them (``puzzlebox/lab/sysid.py``): the
pipeline's world on a recorder, and — for evaluation only — the world's truth beside each log."""

from __future__ import annotations

import dataclasses

from puzzlebox.lab.sysid import TruthTrace  # noqa: E402  (scripts/ is not a package)
from puzzlebox.lab.twin_trial import evaluation_world  # noqa: E402
from puzzlebox.models import PuzzleSpec  # noqa: E402
from puzzlebox.models.generator import paper_family  # noqa: E402
from puzzlebox.models.toggle_log import ToggleLog  # noqa: E402
from puzzlebox.skills.toggle_recorder import ToggleRecorder  # noqa: E402
from puzzlebox.twin.reality import PRESETS, RealityProfile, ScaleRange  # noqa: E402
from puzzlebox.twin.session import TwinSession  # noqa: E402

SPEC = paper_family("train")[0]
"""Doors and slides in a chain: door-0 is free at the start, each part frees the next (door-0, slide-1, door-2, ...)."""


def known_hardware(damping: float, friction: float) -> RealityProfile:
    """The ideal cell (no noise, exact cameras and kinematics) whose box hardware has every kind's joint damping
    and friction at the given multiples of the nominal model's."""
    ideal = PRESETS["ideal"]
    physics = dataclasses.replace(
        ideal.physics,
        kind_joint_damping_scale=ScaleRange(damping, damping),
        kind_joint_friction_scale=ScaleRange(friction, friction),
    )
    return dataclasses.replace(ideal, name=f"hardware-{damping:g}-{friction:g}", physics=physics)


def record(
    profile: RealityProfile | str, parts: tuple[str, ...], seed: int = 0, spec: PuzzleSpec = SPEC
) -> list[ToggleLog]:
    """Open ``parts`` of ``spec`` in that order through the pipeline, every toggle logged, each log with the
    world's true joint trajectory of its part and the cell's true factors as its (evaluation-only) truth."""
    with TwinSession(spec, seed=seed, reality=profile) as session:
        trace = TruthTrace(session.robot, session)
        recorder = ToggleRecorder(trace, {"spec": spec.name, "seed": seed})
        world = evaluation_world(session, recorder, seed=seed)
        recorder.attach(world)
        names = [world.names[m] for m in world.markers]
        for part in parts:
            assert world.try_toggle(names.index(part)).outcome == "moved", part
        kinds = session.cell.kinds.to_dict()
        index = {c.name: i for i, c in enumerate(session.spec.components)}
    for log in recorder.toggles:
        log.truth = {"joint": trace.joint_of(index[log.component], log.time), "kind_factors": kinds}
    return recorder.toggles

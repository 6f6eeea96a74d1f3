"""A scripted sweep: a "ghost hand" opens, one after another, every component no rule holds.

For videos and demonstrations of a box's mechanics without the robot. It pushes each free component's
joint toward its open end with a bounded joint-space force (``qfrc_applied``), so latches still act:
a held component cannot be swept. It reads ground truth (which components are free), so it is an
evaluation tool of the twin, never part of the robot's pipeline.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from puzzlebox.models.kinds import registered_kind
from puzzlebox.twin.session import TwinSession


@dataclass(frozen=True)
class SweepStep:
    """One component the sweep tried: spec name, whether it reached state 1, when [s]."""

    component: str
    opened: bool
    time: float


def sweep_open(
    session: TwinSession,
    on_frame: Callable[[TwinSession], None] | None = None,
    frame_period: float = 1 / 15,
    timeout: float = 3.0,
    duration: float = 1.0,
) -> list[SweepStep]:
    """Open free components in spec order, pass after pass, until the goal is open or nothing moves.

    Args:
        session: the twin (left where the sweep ends).
        on_frame: called every ``frame_period`` of simulated time [s] (e.g. to record video).
        timeout: time allowed per component [s].
        duration: time the ghost hand takes to open one component [s].
    """
    spec = session.spec
    goal = spec.index_of(spec.goal.component)
    dofs = np.array([session.model.jnt_dofadr[session.model.joint(session.scene.names.components[c.name].joint).id]
                     for c in spec.components])  # fmt: skip
    efforts = np.array([registered_kind(c.kind).sweep_effort for c in spec.components])  # the kind's own [N·m or N]
    steps_per_frame = max(1, round(frame_period / session.timestep))
    done: list[SweepStep] = []
    progress = True
    while progress and session.component_states()[goal] != spec.goal.state:
        progress = False
        held = session.latches.held(session.component_states())
        for j in np.flatnonzero((session.component_states() == 0) & ~held):
            start, q0, travel = session.time, session.component_positions()[j], session.travel[j]
            while session.component_states()[j] == 0 and session.time - start < timeout:
                # follow a ramp to the open end with a bounded PD push
                q_des = min(travel, q0 + travel * (session.time - start) / duration)
                error = (q_des - session.component_positions()[j]) / (0.05 * travel)
                qd = session.data.qvel[dofs[j]] * duration / travel
                session.data.qfrc_applied[dofs[j]] = efforts[j] * np.clip(error - 0.5 * qd, -1.0, 1.0)
                session.step(steps_per_frame)
                if on_frame is not None:
                    on_frame(session)
            session.data.qfrc_applied[dofs[j]] = 0.0
            opened = bool(session.component_states()[j] == 1)
            done.append(SweepStep(spec.components[j].name, opened, session.time))
            progress |= opened
            if opened:
                break  # states changed: recompute which components are free
    return done

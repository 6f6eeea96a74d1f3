"""Training episodes of the memory agent end to end in the twin, for ``scripts/train.py --sim twin``.

An episode is a twin trial (:func:`twin_trial.evaluation_world`: perception through the cell's calibration,
the primitives, the F/T outcomes) whose agent learns: what it adds to the memory is its belief, built from
the outcomes the robot sensed, keyed by the poses the robot perceived. The simulator's truth reaches only
the episode's log (whether each try truly moved a part), never the agent. Each stored episode carries its
provenance: ``twin``, the reality profile, and its simulated robot time [s] (from power-up: the survey,
every try, every look).
"""

from __future__ import annotations

from dataclasses import dataclass

from puzzlebox.lab.twin_trial import evaluation_world
from puzzlebox.learning import MemoryAgent, RunResult, run_episode
from puzzlebox.learning.belief import CELL_BELIEF
from puzzlebox.learning.dual_controller import DualControllerConfig
from puzzlebox.models import PuzzleSpec
from puzzlebox.models.calibration import CellCalibration
from puzzlebox.skills import SkillError
from puzzlebox.twin.errors import SimulationDiverged
from puzzlebox.twin.reality import RealityProfile
from puzzlebox.twin.session import TwinSession


@dataclass(frozen=True)
class TwinTraining:
    """Runs training episodes in the twin under ``reality``, perceiving through ``calibration`` (None: the
    twin's nominal calibration, exact only under ``ideal``)."""

    reality: RealityProfile
    calibration: CellCalibration | None = None

    @property
    def controller(self) -> DualControllerConfig:
        """The memory agent's controller in a physical cell (its belief expects a free part to stick now and
        then: ``learning.belief.CELL_BELIEF``), as in the twin trials it is evaluated by."""
        return DualControllerConfig(belief=CELL_BELIEF)

    def episode(self, agent: MemoryAgent, spec: PuzzleSpec, seed: int, max_actions: int) -> RunResult:
        """One episode on ``spec`` with world seed ``seed``; the agent stores it in its memory when it ends.
        A cell that cannot run it (markers not found, the simulation diverged) ends it unsolved and stores
        nothing: the agent saw no outcome."""
        with TwinSession(spec, seed=seed, reality=self.reality) as session:
            agent.episode_source, agent.episode_profile = "twin", self.reality.name
            agent.robot_clock = lambda: session.time
            world = None
            try:
                world = evaluation_world(session, session.robot, self.calibration, seed)
                return run_episode(agent, world, spec.name, seed, max_actions)
            except (SkillError, SimulationDiverged) as err:
                return RunResult(spec.name, seed, False, len(world.log) if world else 0, 0.0,
                                 ended=f"{type(err).__name__}: {err}")  # fmt: skip

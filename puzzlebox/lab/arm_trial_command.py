"""One trial on a real arm as ``trial.py --robot xarm`` asks for it: every input checked before the arm moves (the
address answers, the cell config, the calibration covers its cameras, the agent and its memory), the record
written as it grows (``DIR/runs/``, ``DIR/results.json``), the trial run through :mod:`puzzlebox.lab.real_trial`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from puzzlebox.lab.agent_class import check_agent, make_agent_object
from puzzlebox.lab.cells import RealCell
from puzzlebox.lab.cli import one_line, write_json
from puzzlebox.lab.errors import ArmTrialFailed, ArmTrialRefused
from puzzlebox.lab.real_trial import cell_configs
from puzzlebox.lab.run_store import RunStore
from puzzlebox.lab.trial_config import TrialConfig
from puzzlebox.lab.trials import run_trial
from puzzlebox.learning import LearningError, make_agent, summarise
from puzzlebox.learning.memory import MemoryStore
from puzzlebox.models import SpecError, load_spec
from puzzlebox.models.cell_config import CellConfig
from puzzlebox.models.names import name_slug

__all__ = ["ArmTrialRequest", "reach_arm", "run_arm_trial"]


@dataclass(frozen=True)
class ArmTrialRequest:
    """``trial.py --robot xarm``'s arguments: the arm's address, the cell config and calibration files, the spec of
    the box on the table, the agent (``memory`` its memory file, ``checkpoint`` a deep agent's), the seed and
    budget, the belief's most lockers, the output directory and whether to empty it first."""

    ip: str
    cell: Path
    calibration: Path
    spec: Path
    agent: str
    memory: Path | None
    checkpoint: str | None
    seed: int
    max_actions: int
    max_lockers: int | None
    out: Path
    force: bool


def reach_arm(ip: str, cell: Path, probe: bool = True) -> CellConfig:
    """The cell config at ``cell``, and — with ``probe`` — whether an arm answers at ``ip`` (in about a second):
    what is refused first, before any other check. Raises :class:`ArmTrialRefused`."""
    from puzzlebox.models.cell_config import CellConfigError, load_cell_config
    from puzzlebox.real import RealError, probe_controller

    try:
        config = load_cell_config(cell)
        if probe:
            probe_controller(ip)
    except (CellConfigError, RealError) as err:
        raise ArmTrialRefused(one_line(err)) from err
    return config


def run_arm_trial(request: ArmTrialRequest, arm: Callable[[str, Any], Any] | None = None) -> tuple[dict, Path]:
    """Run the trial ``request`` asks for on the arm ``arm(ip, cell)`` connects to (default ``real.XArmRobot``,
    after probing the address); returns its record and the output directory. Raises :class:`ArmTrialRefused`
    (before the arm moves) or :class:`ArmTrialFailed` (the arm failed a call mid-trial; what was done is kept)."""
    from puzzlebox.models.calibration import CalibrationError, CellCalibration
    from puzzlebox.real import RealError, XArmRobot

    cell = reach_arm(request.ip, request.cell, probe=False)  # probed first by the caller (reach_arm)
    if request.max_actions < 1 or request.seed < 0:
        raise ArmTrialRefused("--max-actions must be >= 1 and --seed >= 0")
    try:
        spec = load_spec(request.spec)
        calibration = CellCalibration.load(request.calibration)
        for camera in (cell.overview_camera, cell.wrist_camera):
            calibration.camera(camera)
    except (SpecError, CalibrationError) as err:
        raise ArmTrialRefused(one_line(err)) from err
    try:
        own = check_agent(request.agent, request.memory, request.checkpoint, request.max_lockers)
        cell_configs(cell)
        memory = MemoryStore.open_existing(request.memory) if request.memory else None
        agent = make_agent_object(request.agent) if own else None
        if agent is None:
            make_agent(request.agent, spec, memory, request.checkpoint, max_lockers=request.max_lockers)
    except (ValueError, LearningError) as err:  # AgentClassError and TrialConfigError are ValueErrors
        raise ArmTrialRefused(one_line(err)) from err

    experiment = {"command": "trial", "robot": "xarm", "ip": request.ip, "cell": cell.to_dict(),
                  "calibration": str(Path(request.calibration).resolve()), "spec": spec.to_dict(),
                  "agent": request.agent, "memory": None if request.memory is None else str(request.memory),
                  "checkpoint": request.checkpoint, "seed": request.seed, "max_actions": request.max_actions,
                  "max_lockers": request.max_lockers}  # fmt: skip
    store = RunStore(request.out, experiment, force=request.force)
    key = f"000-{name_slug(spec.name)}-seed{request.seed}"

    def write(record: dict) -> None:  # the record as it grows: a stop or a crash keeps every action done
        write_json(store.records.path(key), {"key": key, "record": record})
        store.write_results({**summarise([record], request.max_actions), "runs_done": 0, "runs_planned": 1})

    try:
        with (arm or XArmRobot)(request.ip, cell) as robot:
            config = TrialConfig(agent=request.agent, seed=request.seed, max_actions=request.max_actions,
                                 checkpoint=None if request.checkpoint is None else Path(request.checkpoint),
                                 max_lockers=request.max_lockers)  # fmt: skip
            record = run_trial(spec, config, agent=agent, memory=memory, cell=RealCell(robot, cell, calibration),
                               on_record=write).to_dict()  # fmt: skip
    except RealError as err:  # the arm refused or failed a call mid-trial (a stop is in the record instead)
        raise ArmTrialFailed(f"{one_line(err)}; what was done is kept in {request.out}") from err
    store.write_results({**summarise([record], request.max_actions), "runs_done": 1, "runs_planned": 1})
    return record, request.out

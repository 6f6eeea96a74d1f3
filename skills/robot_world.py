"""``RobotWorld``: the ``World`` protocol over a robot — perception in, primitives out.

It works on any :class:`models.robot.Robot` (the twin's or a real arm's) with the cell's calibration
file; it never sees simulator ground truth.

``observe()`` gives the components as perceived at the start, in an order shuffled by the seed, with
states the world tracks from its own outcomes. Perception (:class:`skills.scene_survey.SceneSurvey`)
looks from the overview camera, then measures close up from the wrist camera every marker the overview
missed, saw at a grazing angle or could not pose within the reprojection bound.

``try_toggle(i)`` runs the toggle primitive on component ``i`` and returns ``moved``, ``blocked`` (felt
held through the F/T sensor: evidence of a lock) or ``failed`` with its reason (the grasp closed on
nothing, slipped, IK, the force limit: no evidence). A failed try is retried within ``max_retries``,
each time after measuring the component's marker again close up (a grasp that missed is most often a
pose that was off); a component that still fails is reported with ``give_up``, never looped on. A try
stopped after the grasp carried the handle past ``moved_fraction`` of its travel is checked against the
overview first: a part that did move is not tried again.
"moved" is checked against the marker re-observed — by the overview camera when the overview trusted
that marker at the start, else close up from the wrist camera — (a marker that left its closed pose, or
vanished, as a door's does when it stands open, moved; one still at its closed pose after a "moved"
means the handle slipped out of the pads: with a weak grip a latched door's did, with hardly any force).

A part that will not move as its kind says (a misread marker: the pipeline was told its kind wrong) is tried as the
other kinds its perceived geometry allows, in the same try (:mod:`skills.other_kinds`). The rule: a part not
yet moved as the kind in use is tried as other kinds (i) when the world would give it up (every attempt failed: as that
kind the fingers closed on nothing, or the path carried nothing), or (ii) when it is blocked as that kind a second time.
A first blocked try is never second-guessed: the pull of a wrong kind's path reads exactly as a lock does, and a lock is
what the agent learns from it. From the second on, the other kinds are tried after the kind in use held (robot time, not
an action), and the outcome stays ``blocked`` unless one of them moves the part: a locked part is held whatever path
pulls it, so the agent still learns its locks from every blocked try. The candidates: registered kinds whose ``lift``
fits the marker's perceived height above the lid and whose handle is not where a grasp on the part closed on nothing;
those of the family of the kinds the world was told (the paper's, when all are) first, then — after a grasp that held
the handle — those with their handle where the kind in use has it, then in registration order; at most
``WorldConfig.other_kinds`` a try, one attempt each, every motion in contact at half pace
(``Toggler.toggle(careful=True)``: the path may meet a post where none was expected), in at most ``other_kind_rounds``
tries of a part. A kind that moves the part is kept for every later try of it and observed (:meth:`RobotWorld.observe`,
:attr:`RobotWorld.found_kinds`); one whose grasp held where the kind in use closed on nothing, or that carried a door
part of the way, is used (and observed) from then on; if none moves it, the outcome is ``blocked`` when any grasp felt
the part held, else the first outcome.

:attr:`RobotWorld.log` records each try as sensed and — only when an evaluator passes
``ground_truth`` — the simulator's truth beside it, for scoring.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from puzzlebox.models import ComponentObservation, SceneObservation, TryResult
from puzzlebox.models.calibration import CellCalibration
from puzzlebox.models.geometry import wrap_angle
from puzzlebox.models.kinds import get_kind
from puzzlebox.models.robot import Robot
from puzzlebox.models.try_outcome import Cause, ReadsItsResult
from puzzlebox.skills.door_clearance import lean_away, near_open_door
from puzzlebox.skills.joint_model import JointModel, joint_model
from puzzlebox.skills.other_kinds import OtherKinds
from puzzlebox.skills.perception import MarkerDetection, MarkerDetector, kind_of, lid_height, upright_pose
from puzzlebox.skills.primitives import PrimitiveConfig, Toggler, ToggleResult
from puzzlebox.skills.scene_survey import SceneSurvey, SurveyConfig
from puzzlebox.skills.toggle_result import LATCHED

MOVED_DISTANCE = 0.01
"""A re-observed marker this far from its closed pose has moved [m]..."""
MOVED_ANGLE = math.radians(20)
"""... or turned this much [rad]."""
DOOR_STAYED = "SlipDetected: the door stayed shut"
"""Reason of a try whose fingers went the whole way while the door's marker stayed at its closed pose."""
HELD_UNDER_PINCH_AND_PUSH = LATCHED[Cause.LOCKED_PINCH_AND_PUSH]
"""Reason of a door seen shut after a pinch and then a push both went the whole way: held (a latch or a jam). The
push's own reading can miss it: on a latched door whose post the pad rode over before the load reached
``push.blocked_force`` (28 N of 30), and which it then pressed on something else near the end of the arc."""


def _stopped_descending(result: ToggleResult) -> bool:
    """Whether a toggle ended with the force guard stopping the fingers on their way down: the pinch's or the
    push's descent, or that of the push on under a door's plate that followed a push run short."""
    last = result.last_stop()
    return not result.not_pushed and last.cause is Cause.FORCE_LIMIT and last.stopped_while == "descending"


@dataclass
class _Effort:
    """What the tries of one action cost: the largest filtered wrist force [N], the simulated and wall time [s]
    and the toggles made."""

    peak: float = 0.0
    sim_time: float = 0.0
    wall_time: float = 0.0
    attempts: int = 0

    def add(self, result: ToggleResult) -> None:
        self.peak = max(self.peak, result.peak_force)
        self.sim_time = self.sim_time + result.sim_time
        self.wall_time = self.wall_time + result.wall_time


@dataclass(frozen=True)
class WorldConfig:
    """How the world turns tries into outcomes."""

    max_retries: int = 2
    """Extra attempts after a failed try, each after a close-up look at the marker."""
    remeasure_limit: float = 0.02
    """A close-up measurement this far from the pose in use replaces it only for a closed component
    whose marker did not move [m]: farther means the part moved (or another marker was read)."""
    door_look_offset: float = 0.10
    """How far towards its hinge from a door's closed marker the wrist camera looks down from, to see where
    the door stands [m]: from straight above, a door raised 40 deg shows its marker behind its own handle
    (not detected); from 10 cm over (~22 deg off the vertical at the close-up height), face on to a
    half-open door and clear of the handle."""
    open_door_from: float = 0.6
    """Lowest fraction of its travel at which a door believed open may stand (opened past ``moved_fraction``,
    0.75, it may sink back a few degrees under its own weight) [-]; one a failed try left part-way may stand
    anywhere above ``blocked_progress``."""
    door_clearance: float = 0.045
    """A grasp point this close to where an open door may overhang (:mod:`skills.door_clearance`) is descended
    onto cautiously [m]: the fingers, 42 mm apart and 30 mm wide, reach ~30 mm from it, and the door's pose
    is known to ~5 mm."""
    shut_blocked_doors: bool = True
    """After a door's opening try ends ``blocked``, look where it stands (:meth:`RobotWorld._fraction_open`) and push
    it shut from there if it stands past ``blocked_progress``: balanced on its hinge, a locked door carried to its
    lock's wall (~20-30 % of its travel) by a push, or lifted by tries as other kinds, stays there; standing raised
    it hid the slide beside it from the next grasp (closed on nothing five times), and the next push from where it
    stood met the post at 47 N."""
    other_kinds: int = 2
    """Most other kinds a part that will not move as its kind says is tried as, in one try (module docstring);
    0: never."""
    other_kind_rounds: int = 2
    """Most tries of one part in which it is tried as other kinds."""
    other_kinds_cautious: bool = True
    """Descend cautiously (``toggle(cautious=True)``) onto another kind's grasp point that an open door may overhang
    (:meth:`RobotWorld._doors_overhanging`), the part's own door included: tried as other kinds after its tries as a
    door failed part-way, the part may stand raised over their handles. Tried as a slide at the normal descent
    (~3 cm/s, careful), a pad met the handle of the part's own door (left part-way by a pinch that slipped, sunk to
    57 deg) 47 mm above the slide's grasp point (the light touch watches the last 18 mm only), pushed it up to 77 deg,
    where a downward push has little lever about the hinge, and the load rose ~1.1 N a tick to 66.8 N true before the
    late, filtered reading passed the 60 N guard (hard-chain8-s36016 seed 36100, harsh). Cautious, the same descent
    stopped at 17.8 N true."""
    lift_tolerance: float = 0.012
    """A kind fits a marker perceived this close to the kind's ``lift`` above the lid [m] (a lever's marker stands
    30 mm up; close up, markers are measured within ~1 mm)."""
    same_handle: float = 0.015
    """Two kinds whose grasp points at a marker's perceived pose lie this close grasp the same handle [m] (the
    handle post is 12 mm wide; other kinds' handles stand 70 mm apart)."""
    survey: SurveyConfig = field(default_factory=SurveyConfig)
    primitives: PrimitiveConfig = field(default_factory=PrimitiveConfig)
    """The primitives' config (force limit, latch threshold...): a real cell's comes from its cell config
    (``PrimitiveConfig.for_cell``)."""


@dataclass
class ActionLog(ReadsItsResult):
    """One try as the robot sensed it (and, for evaluation, the truth): the world's result as it returned it (the
    same frozen :class:`models.TryResult`) with what the try cost."""

    index: int
    marker: int
    kind: str
    result: TryResult
    progress: float
    peak_force: float
    """Largest filtered wrist force over the try, including retries [N]."""
    attempts: int
    sim_time: float
    wall_time: float
    true_moved: bool | None = None
    tried_kinds: tuple[str, ...] = ()
    """The other kinds the part was tried as in this try, in order (``kind`` is the one in use after it)."""
    opening: bool | None = None
    """Whether the try was to open the part (True: from its closed state as the world believed it) or to close it."""

    def to_dict(self) -> dict[str, Any]:
        """The try as a record's ``timeline`` entry."""
        return {
            "index": self.index, "marker": self.marker, "kind": self.kind, "outcome": self.outcome,
            "reason": self.reason, "moved": self.moved, "progress": self.progress, "peak_force": self.peak_force,
            "attempts": self.attempts, "sim_time": self.sim_time, "wall_time": self.wall_time,
            "true_moved": self.true_moved, "tried_kinds": self.tried_kinds, "cause": self.cause,
            "opening": self.opening,
        }  # fmt: skip


@dataclass
class RobotWorld:
    """See the module docstring. ``robot`` satisfies :class:`models.robot.Robot`; ``calibration`` is the
    cell's camera calibration; ``marker_map`` maps marker ids to kinds; ``goal_marker`` is the id on the
    component that must reach ``goal_state``."""

    robot: Robot
    calibration: CellCalibration
    marker_map: dict[int, str]
    goal_marker: int
    goal_state: int = 1
    seed: int = 0
    config: WorldConfig = field(default_factory=WorldConfig)
    ground_truth: Callable[[int], int] | None = None
    """Evaluation only: marker id -> the simulator's state of that component (never used to decide)."""
    names: dict[int, str] | None = None
    """Evaluation only: marker id -> the spec's component name, for result files."""
    log: list[ActionLog] = field(default_factory=list)
    unsettled: set[int] = field(default_factory=set)
    """Markers of doors a failed try left possibly part-way where no look could see them: looked at before
    they are tried again."""
    detector: MarkerDetector | None = None
    """The marker detector every look uses (default a new :class:`MarkerDetector`); a recorder may pass one
    that also keeps what it found, so a video shows the pipeline's own detections."""

    def __post_init__(self) -> None:
        self.other_kinds = OtherKinds(self)
        """Tries a part as kinds it was not told."""
        self.kinds = dict(self.marker_map)
        """Marker id -> the kind its part is handled as: the told kind until another moved it (module docstring)."""
        self.found_kinds: dict[int, str] = {}
        """Marker id -> the kind that moved its part, where that is not the kind the world was told."""
        self.moved_as: set[int] = set()
        """Markers whose part moved as the kind in use: never tried as another."""
        self.blocked_as: set[int] = set()
        """Markers whose part was blocked as the kind in use."""
        self.other_kind_rounds: dict[int, int] = {}
        """Marker id -> tries in which its part was tried as other kinds."""
        self.empty_handles: dict[int, list[np.ndarray]] = {}
        """Marker id -> grasp points [m] where a grasp on its part closed on nothing: no handle stands there."""
        self.detector = self.detector or MarkerDetector()
        self.toggler = Toggler(self.robot, self.config.primitives)
        lifts = {m: get_kind(kind).lift for m, kind in self.marker_map.items()}  # a lever's marker stands higher
        self.survey = SceneSurvey(
            self.robot, self.calibration, self.toggler, self.detector, self.config.survey, marker_lifts=lifts
        )
        found = self.survey.locate(set(self.marker_map))
        self.lid_height = lid_height(found, lifts)
        order = np.random.default_rng(self.seed).permutation(sorted(self.marker_map))
        self.markers = [int(m) for m in order]
        self.closed_poses = {m: found[m].planar_pose for m in self.markers}
        self.marker_heights = {m: float(found[m].T_base_marker[2, 3]) - self.lid_height for m in self.markers}
        """Marker id -> its marker's perceived height above the lid [m] (a kind's ``lift``: what kinds it can be)."""
        self.seen_by_overview = set(self.survey.overview_trusted)
        self.joint_models: dict[int, JointModel] = {m: self._joint_model(m) for m in self.markers}
        self.states = np.zeros(len(self.markers), dtype=np.int64)

    def _joint_model(self, marker: int, kind: str | None = None) -> JointModel:
        """``marker``'s joint as ``kind`` (default: the kind in use) at its perceived closed pose."""
        kind = kind or kind_of(self.kinds, marker)
        return joint_model(kind, upright_pose(self.closed_poses[marker], self.lid_height))

    def observe(self) -> SceneObservation:
        """The parts as perceived at the start, each of the kind it is handled as: the kind the world was told, or
        the one that moved it where another did (:attr:`found_kinds`), or whose grasp held where the told kind's
        closed on nothing."""
        kinds = [kind_of(self.kinds, m) for m in self.markers]
        components = tuple(
            ComponentObservation(kind, self.closed_poses[m].copy(), int(s))
            for kind, m, s in zip(kinds, self.markers, self.states, strict=True)
        )
        return SceneObservation(components, goal_index=self.markers.index(self.goal_marker), goal_state=self.goal_state)

    def try_toggle(self, index: int) -> TryResult:
        marker = self.markers[index]
        opening = self.states[index] == 0
        before = self.ground_truth(marker) if self.ground_truth else None
        effort = _Effort()
        result, failures, empty = self._retried(marker, opening, effort)
        outcome = self._sensed_outcome(result, marker, opening)
        if self._door_stayed_shut(outcome, marker):
            # the fingers went the whole way and the door stayed: weak pads slid along its post (a latch,
            # or a door heavier than they hold). A push tells which: it turns a free door, a latch holds it.
            result = self.toggler.toggle(self.joint_models[marker], opening, push=True)
            effort.attempts += 1
            effort.add(result)
            outcome = self._sensed_outcome(result, marker, opening)
            if self._door_stayed_shut(outcome, marker):
                outcome = TryResult("blocked", HELD_UNDER_PINCH_AND_PUSH, cause=Cause.LOCKED_PINCH_AND_PUSH)
        tried: tuple[str, ...] = ()
        if self.other_kinds.due(marker, outcome, failures):
            outcome, other, tried = self.other_kinds.try_them(marker, opening, outcome, empty)
            effort.attempts += len(tried)
            if other is not None:
                result = other
                effort.add(other)
        if opening and outcome.outcome == "blocked" and self._swings_up(marker) and self.config.shut_blocked_doors:
            self._shut_if_raised(marker, effort)
        if outcome.moved:
            self.states[index] ^= 1
            self.moved_as.add(marker)
            if self.kinds[marker] != kind_of(self.marker_map, marker):  # (a kind used since a grasp held as it)
                self.found_kinds[marker] = self.kinds[marker]
        elif outcome.outcome == "blocked":
            self.blocked_as.add(marker)
        if outcome.outcome == "failed" and failures > self.config.max_retries:
            outcome = TryResult(
                "failed", f"{outcome.reason} ({effort.attempts} attempts)", give_up=True, cause=outcome.cause
            )
        after = self.ground_truth(marker) if self.ground_truth else None
        self.log.append(
            ActionLog(
                index, marker, kind_of(self.kinds, marker), outcome, result.progress, effort.peak, effort.attempts,
                effort.sim_time, effort.wall_time, None if before is None else bool(before != after), tried,
                bool(opening),
            )
        )  # fmt: skip
        return outcome

    def _retried(self, marker: int, opening: bool, effort: _Effort) -> tuple[ToggleResult, int, bool]:
        """Toggle ``marker``'s part as the kind in use, retrying a failed try up to ``max_retries`` times (leaning
        less, topping up the doors over it, looking where a door stands, measuring the part again); the tries'
        cost goes to ``effort``. Gives the last toggle's result, how many failed, and whether a grasp closed on
        nothing where the kind in use has its handle."""
        failures = 0
        is_door = self._swings_up(marker)  # (a door, or any kind that swings up out of the lid plane)
        door_at = None
        raised = False  # a door left part-way where no look sees it
        if marker in self.unsettled and opening:  # a door an earlier try left part-way: where is it now?
            door_at = self._fraction_open(marker)
            raised = door_at is None
        self.unsettled.discard(marker)
        overhanging = self._doors_overhanging(marker, opening)
        jm = self.joint_models[marker]
        lean = lean_away([self.joint_models[d] for d in overhanging], *(jm.grasp_point_at(f) for f in (0.0, 1.0)))
        empty = False
        judgement = self.toggler.config.judgement
        for attempt in range(1 + self.config.max_retries):
            effort.attempts = attempt + 1
            stands_at = self._stands_at(marker)
            result: ToggleResult = self.toggler.toggle(
                self.joint_models[marker],
                opening,
                where_is=lambda: self._fraction_open(marker),
                door_at=door_at,
                raised=raised,
                cautious=bool(overhanging),
                lean=lean,
                stands_at=stands_at,
            )
            effort.add(result)
            empty = empty or result.closed_on_nothing
            if result.outcome == "failed" and result.progress >= judgement.moved_fraction:
                # stopped (force limit, slip) after carrying the handle most of the way: look before retrying
                # (a door's marker must be seen where an open door's is: one the pads let go part-way hides
                # it behind its own raised handle, as an open one shows it edge-on)
                if self._overview_verdict(marker, opening, unseen_moved=not is_door).moved:
                    result.seen_moved()
            if result.outcome != "failed":
                break
            failures += 1
            if lean is not None and result.cause is Cause.UNREACHABLE:
                # leaning out of reach (tilted 20 deg outwards, the flange stands ~6 cm further out): half as much
                # next time (10 deg still cleared a post), then upright
                lean = 0.5 * lean if np.linalg.norm(lean) > 0.75 else None
            if attempt < self.config.max_retries and overhanging and _stopped_descending(result):
                # the fingers met something on the way down beside a door that may stand short of its stop,
                # leaning over this part: push that door up into its stop, then descend again
                for door in overhanging:
                    effort.add(self.toggler.toggle(self.joint_models[door], True, raised=True))
            if attempt < self.config.max_retries and is_door:
                door_at = self._fraction_open(marker)  # a failed try may leave a door part-way: see where
                # part-way and unseen: a pinch would descend onto it (195 N); it is pushed up under its plate
                raised = door_at is None and result.progress >= judgement.blocked_progress
            if (
                attempt < self.config.max_retries
                and opening
                and not raised
                and (door_at is None or abs(door_at) < 0.05)
            ):
                self._remeasure(marker)  # only a closed part shows its closed pose
        if is_door and opening and result.outcome == "failed" and result.progress >= judgement.blocked_progress:
            self.unsettled.add(marker)  # the next try of it looks first
        return result, failures, empty

    def _shut_if_raised(self, marker: int, effort: _Effort) -> None:
        """Push ``marker``'s door (its opening try just ended ``blocked``) shut from where a look sees it stand, if
        past ``blocked_progress`` of its travel (:attr:`WorldConfig.shut_blocked_doors`); its cost goes to
        ``effort``. A door the look does not see is left as it is (a blocked door stands low, where it is seen)."""
        at = self._fraction_open(marker)
        if at is None or at < self.toggler.config.judgement.blocked_progress:
            return
        effort.add(self.toggler.toggle(self.joint_models[marker], False, door_at=at))
        self.unsettled.discard(marker)

    def _doors_overhanging(self, marker: int, opening: bool) -> list[int]:
        """The other doors that may stand open (believed open, or left part-way by a failed try) over where
        ``marker``'s part is grasped (:mod:`skills.door_clearance`): its descents are then made slowly and
        stopped at a light touch."""
        c, jm = self.config, self.joint_models[marker]
        grasp = jm.grasp_point_at(0.0 if opening else 1.0)
        doors = []
        for other, state in zip(self.markers, self.states, strict=True):
            if other == marker or not self._swings_up(other):
                continue
            lowest = self._lowest_open(other, int(state))
            if lowest is not None and near_open_door(self.joint_models[other], lowest, grasp, c.door_clearance):
                doors.append(other)
        return doors

    def _lowest_open(self, marker: int, state: int) -> float | None:
        """The lowest fraction of its travel the door on ``marker``, believed in ``state``, may stand open at: left
        part-way by a failed try (``blocked_progress``), believed open (``open_door_from``), or None: shut."""
        if marker in self.unsettled:
            return self.toggler.config.judgement.blocked_progress
        return self.config.open_door_from if state == 1 else None

    def _door_stayed_shut(self, outcome: TryResult, marker: int) -> bool:
        """Whether a pinch that carried its fingers the whole way left a door seen shut (its marker where
        it was): the signature of pads sliding along the post of a door they could not turn."""
        stayed = outcome.cause is Cause.DOOR_STAYED_SHUT  # (opening only)
        return self.toggler.config.door_push and self._swings_up(marker) and stayed

    def _fraction_open(self, marker: int) -> float | None:
        """Fraction of its travel at which ``marker``'s part stands now (0 closed, 1 open), from its marker
        measured close up (the wrist camera above its closed pose: a door's marker turns with it, trusted up to
        ``max_view_angle_deg``); None if not seen."""
        jm = self.joint_models[marker]
        closed = self._closed_point(marker)
        look_at = closed
        if jm.handling.swings_up:  # from over its hinge side (see WorldConfig.door_look_offset)
            out = closed - jm.origin
            out -= np.dot(out, jm.axis) * jm.axis
            out[2] = 0.0
            look_at = closed - self.config.door_look_offset * out / np.linalg.norm(out)
        seen = self.survey.close_up_turning(marker, look_at, self.lid_height)
        if seen is None:
            return None
        return jm.fraction_between(closed, seen.T_base_marker[:3, 3])

    def _stands_at(self, marker: int) -> float | None:
        """Where a part whose small motion is read from its marker close up and that does not swing up (a lever)
        stands before a try (fraction of its travel; :attr:`Pinch.head_start`), or None: not looked at."""
        handling = self.joint_models[marker].handling
        if handling.swings_up or handling.verdict != "arc" or not handling.read_close_up:
            return None
        return self._fraction_open(marker)

    def _closed_point(self, marker: int) -> np.ndarray:
        """Where ``marker``'s centre is with its part closed, in the base frame [m]."""
        return np.array([*self.closed_poses[marker][:2], self.lid_height + get_kind(self.kinds[marker]).lift])

    def _remeasure(self, marker: int) -> None:
        """Measure ``marker`` again close up and use it if it is still near its closed pose."""
        seen = self.survey.close_up(marker, self.closed_poses[marker], self.lid_height)
        if seen is None:
            return
        pose = seen.planar_pose
        if np.linalg.norm(pose[:2] - self.closed_poses[marker][:2]) < self.config.remeasure_limit:
            self.closed_poses[marker] = pose
            self.joint_models[marker] = self._joint_model(marker)

    def _sensed_outcome(self, result: ToggleResult, marker: int, opening: bool) -> TryResult:
        if result.outcome != "moved":
            return TryResult(result.outcome, result.reason, cause=result.cause)
        return self._overview_verdict(marker, opening)

    def _overview_verdict(self, marker: int, opening: bool, unseen_moved: bool = True) -> TryResult:
        """Whether the overview agrees that ``marker``'s part moved (``moved``) or shows it where it was
        (``failed``: slipped); when the overview has no trusted view of it, ``moved`` if ``unseen_moved``."""
        if marker not in self.seen_by_overview or self.joint_models[marker].handling.read_close_up:
            # a small motion is read close up (a lever's marker moves 12 mm; its tilt, 19 deg, read from the
            # overview put a lever left at 2 deg at 7 deg, close up at 5 deg: its centre is read within 1 deg)
            return self._close_up_verdict(marker, opening, unseen_moved)
        seen = [d for d in self.survey.overview() if d.marker_id == marker]
        if not seen:
            # a door standing open shows its marker edge-on: it left its closed pose; anything else
            # hidden (the arm?) leaves the primitive's verdict standing
            if unseen_moved:
                return TryResult("moved")
            return TryResult("failed", "SlipDetected: the part was not seen", cause=Cause.MARKER_LOST)
        return self._verdict(seen[0], marker, opening)

    def _close_up_verdict(self, marker: int, opening: bool, unseen_moved: bool = True) -> TryResult:
        """As :meth:`_overview_verdict` for a marker the overview does not see well, from the wrist camera
        straight above the marker's closed pose: a weakly held handle can slide out of the pads while the
        fingers travel the whole path with hardly any force (a latched door at a 10 N grip), and only a
        look tells that from a move. Not seen there: an opened part left its closed pose (a door's marker
        stands edge-on), a closed one did not come back; the arm out of reach leaves the primitive's
        verdict standing."""
        seen = self.survey.close_up(marker, self.closed_poses[marker], self.lid_height)
        is_door = self._swings_up(marker)
        if seen is None and opening and is_door and self.survey.last_close_up_reached:
            # from straight above, a door raised 20-50 deg shows its marker tilted and offset (often not read):
            # from over its hinge side a door short of ~50 deg is seen, one standing open is not
            at = self._fraction_open(marker)
            if at is not None:
                return self._door_verdict(at, opening)
        if seen is None:
            if (opening and unseen_moved) or not self.survey.last_close_up_reached:
                return TryResult("moved")
            return TryResult(
                "failed", "SlipDetected: the handle moved but the part is not back at its closed pose",
                cause=Cause.NOT_BACK_CLOSED,
            )  # fmt: skip
        return self._verdict(seen, marker, opening)

    def _verdict(self, seen: MarkerDetection, marker: int, opening: bool) -> TryResult:
        """``moved`` if the marker ``seen`` is where the part's other state puts it, as its kind's
        ``Handling.verdict`` reads it: ``arc``, by the fraction of its travel the marker centre turned about the
        hinge (a door let go part-way has left its closed pose too; a lever's marker, 12 mm, read close up);
        ``left_pose``, by having left its closed pose (``MOVED_DISTANCE``, ``MOVED_ANGLE``) or not."""
        jm = self.joint_models[marker]
        if jm.handling.verdict == "arc":
            at = jm.fraction_between(self._closed_point(marker), seen.T_base_marker[:3, 3])
            return self._door_verdict(at, opening)
        delta = seen.planar_pose - self.closed_poses[marker]
        turn = abs(wrap_angle(delta[2]))
        away = bool(np.linalg.norm(delta[:2]) > MOVED_DISTANCE or turn > MOVED_ANGLE)
        if away == opening:
            return TryResult("moved")
        return TryResult("failed", "SlipDetected: the handle moved but the marker did not", cause=Cause.MARKER_STILL)

    def _door_verdict(self, at: float, opening: bool) -> TryResult:
        """Whether a part (a door, a lever) seen at fraction ``at`` of its travel reached its other state."""
        c = self.toggler.config
        if (at >= c.judgement.moved_fraction) if opening else (at <= 1.0 - c.judgement.moved_fraction):
            return TryResult("moved")
        if opening and at < c.judgement.blocked_progress:
            return TryResult("failed", f"{DOOR_STAYED} ({at:.0%} of its travel)", cause=Cause.DOOR_STAYED_SHUT)
        return TryResult(
            "failed", f"SlipDetected: the part stands at {at:.0%} of its travel", cause=Cause.STANDS_PART_WAY
        )

    def _swings_up(self, marker: int) -> bool:
        """Whether ``marker``'s part swings up out of the lid plane (a door: ``Handling.swings_up``)."""
        return self.joint_models[marker].handling.swings_up

    def ground_truth_name(self, index: int) -> str:
        """For logs: the spec name of component ``index`` when given, else its marker id."""
        marker = self.markers[index]
        return self.names[marker] if self.names else f"marker-{marker}"

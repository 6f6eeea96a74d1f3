"""The puzzle box of a spec alone, as a MuJoCo model: no table, no robot, nothing but the box and a light.

What the box is, and what it does, without the twin: its lock mechanisms (``locks="contact"``) block by contact
in plain MuJoCo, so ``box.xml`` is the model to hand to another simulator, to a GPU batch engine, to a printer's
slicer or to :func:`models.lock_check.check_locks`. Rules no mechanism realizes
(:func:`models.mechanism_mjcf.mechanism_layout`) hold nowhere here: their latches (``<c>:latch``) are in the
model but inactive, as at the start of a twin's session.

Frames: the world frame is the lid frame (origin at the centre of the lid's top face, x along the box's
length, z up) [m]; the lid body is fixed there (the box stands on nothing: its shell hangs below z = 0). Names as
:func:`models.puzzle_box.build_puzzle_box` makes them: component ``c``'s joint is ``<prefix>:joint``, its
prefix :func:`models.puzzle_box.component_prefixes` (joint ranges in radians for a hinge, metres for a slide).

The physics options are the twin scene's (:func:`models.scene.build_scene`): 2 ms steps, the implicit-fast
integrator, elliptic friction cones with impratio 10, and no silent reset on divergence, so a part behaves here
as in the scene.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
from dm_control import mjcf

from puzzlebox.models.atomic import write_atomically, write_text_atomically
from puzzlebox.models.errors import ModelsError
from puzzlebox.models.mechanism_mjcf import LOCK_MODES, LockMode
from puzzlebox.models.puzzle_box import build_puzzle_box, component_prefixes
from puzzlebox.models.spec import PuzzleSpec

__all__ = ["BOX_XML", "TIMESTEP", "NotAPuzzleBox", "build_box_model", "compile_box", "export_box"]

BOX_XML = "box.xml"
"""File name of the exported box model in its directory."""
TIMESTEP = 0.002
"""Physics step [s], the scene's (``models.scene.SceneConfig.timestep``)."""


class NotAPuzzleBox(ModelsError, ValueError):
    """A spec with no box (a disassembly scene): there is no box model to build."""


def build_box_model(spec: PuzzleSpec, locks: LockMode = "contact") -> mjcf.RootElement:
    """The box of ``spec`` alone (module docstring): :func:`models.puzzle_box.build_puzzle_box` with its
    markers, the lid frame at the world origin, radians, the scene's physics options and a light to render by.

    ``locks``: ``"contact"`` (mechanisms that block by contact) or ``"latch"`` (no mechanism: nothing holds a
    part but its joint range). Raises :class:`NotAPuzzleBox` for a spec with no box,
    :class:`models.errors.UnknownKindError` for a kind no module builds, ``ValueError`` for another ``locks``."""
    if locks not in LOCK_MODES:
        raise ValueError(f"locks must be one of {LOCK_MODES}, got {locks!r}")
    if spec.box is None:
        raise NotAPuzzleBox(f"spec {spec.name!r} is a disassembly scene (no box); only puzzle boxes build as a box")
    root = build_puzzle_box(spec, with_markers=True, locks=locks)
    root.compiler.angle = "radian"  # the box's joint ranges are in radians; MJCF reads degrees by default
    root.option.timestep = TIMESTEP
    root.option.integrator = "implicitfast"
    root.option.cone = "elliptic"  # as the scene (models.scene): the same contacts as in the twin
    root.option.impratio = 10
    root.option.flag.autoreset = "disable"  # divergence must show as a warning, never as a silent reset
    root.visual.headlight.ambient = [0.25, 0.25, 0.25]
    root.visual.headlight.diffuse = [0.3, 0.3, 0.3]
    _, _, height = spec.box.size
    root.worldbody.add(
        "light",
        name="key_light",
        pos=[0.1, -0.1, height + 1.0],
        dir=[-0.1, 0.1, -1],
        directional=True,
        castshadow=True,
        diffuse=[0.55, 0.55, 0.55],
    )
    return root


def export_box(spec: PuzzleSpec, out_dir: str | Path, locks: LockMode = "contact") -> Path:
    """Write ``out_dir/box.xml`` (:func:`build_box_model`) and its assets (the markers' textures) into
    ``out_dir`` (created), each file atomically, ``box.xml`` last: where it exists, its assets are whole.
    Loadable by plain ``mujoco.MjModel.from_xml_path``. Returns the path of ``box.xml``."""
    root = build_box_model(spec, locks)
    out = Path(out_dir)
    for filename, contents in root.get_assets().items():
        write_atomically(out / filename, lambda tmp, contents=contents: tmp.write_bytes(contents))
    return write_text_atomically(out / BOX_XML, root.to_xml_string())


def compile_box(spec: PuzzleSpec, locks: LockMode = "contact") -> tuple[mujoco.MjModel, dict[str, str]]:
    """The compiled box model of :func:`build_box_model` and the MuJoCo name of each component's joint, by spec
    name: what :func:`models.lock_check.check_locks` takes."""
    root = build_box_model(spec, locks)
    model = mujoco.MjModel.from_xml_string(root.to_xml_string(), assets=root.get_assets())
    joints = {name: f"{prefix}:joint" for name, prefix in component_prefixes(spec).items()}
    return model, joints

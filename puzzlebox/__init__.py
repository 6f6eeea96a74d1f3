"""puzzlebox: a MuJoCo digital twin of locking puzzle boxes and the memory-based agents that learn to open them.

One import root. The layers (DESIGN.md) are subpackages: :mod:`puzzlebox.models` (specs, kinds, generators,
MuJoCo models), :mod:`puzzlebox.twin` (the simulated cell), :mod:`puzzlebox.skills` (perception and motion
primitives behind the ``Robot`` seam), :mod:`puzzlebox.learning` (agents, memory, symbolic simulator),
:mod:`puzzlebox.real` (the real xArm-7 driver) and :mod:`puzzlebox.lab` (the composition layer: trials, sweeps,
experiments). Importing ``puzzlebox`` imports none of them; it registers the gymnasium environments
``puzzlebox/Puzzle-v0`` (the symbolic simulator), ``puzzlebox/TwinPuzzle-v0`` (the twin at the option level) and
``puzzlebox/BoxManipulation-v0`` (the twin at the low level, the arm at 20 Hz).
"""

__version__ = "0.1.0"

_MUJOCO_GL_VALUES = ("egl", "osmesa", "glfw", "glx", "", "enable", "enabled", "on", "true", "1", "disable",
                     "disabled", "off", "false", "0")  # fmt: skip
"""The values of ``MUJOCO_GL`` MuJoCo accepts on Linux (``mujoco.rendering.classic.gl_context``)."""


def _refuse_a_script_an_unknown_mujoco_gl() -> None:
    """A command-line script (``scripts/*.py``) started with a ``MUJOCO_GL`` MuJoCo does not know says so in one line
    (exit 2): MuJoCo refuses it with a 20-line traceback at its first import, before the script's own checks run, and
    every script imports ``puzzlebox`` before anything of MuJoCo. A library user meets MuJoCo's own error."""
    import os
    import sys
    from importlib.util import find_spec
    from pathlib import Path

    gl = os.environ.get("MUJOCO_GL")
    if gl is None or gl.strip().lower() in _MUJOCO_GL_VALUES or not sys.argv or not sys.argv[0]:
        return
    scripts = find_spec("puzzlebox.scripts")
    folders = [Path(f).resolve() for f in (scripts.submodule_search_locations or [])] if scripts else []
    if Path(sys.argv[0]).resolve().parent in folders:
        sys.stderr.write(f"error: MUJOCO_GL={gl!r} is not a value MuJoCo knows: egl (headless), osmesa, glfw or glx, "
                         "or unset\n")  # fmt: skip
        raise SystemExit(2)


def _register_environments() -> None:
    """``gymnasium.make("puzzlebox/TwinPuzzle-v0", spec=..., config=...)`` and
    ``gymnasium.make("puzzlebox/BoxManipulation-v0", spec=..., obs_mode=..., reward_mode=...)``: registered on
    ``import puzzlebox`` (or ``gymnasium.make("puzzlebox:puzzlebox/...", ...)``), each imported only when made."""
    import gymnasium

    if "puzzlebox/Puzzle-v0" not in gymnasium.registry:  # (the symbolic one, also registered by puzzlebox.learning)
        gymnasium.register(id="puzzlebox/Puzzle-v0", entry_point="puzzlebox.learning.puzzle_env:PuzzleEnv")
    if "puzzlebox/TwinPuzzle-v0" not in gymnasium.registry:
        gymnasium.register(id="puzzlebox/TwinPuzzle-v0", entry_point="puzzlebox.lab.twin_puzzle_env:TwinPuzzleEnv")
    if "puzzlebox/BoxManipulation-v0" not in gymnasium.registry:
        gymnasium.register(
            id="puzzlebox/BoxManipulation-v0", entry_point="puzzlebox.lab.box_manipulation_env:BoxManipulationEnv"
        )


_refuse_a_script_an_unknown_mujoco_gl()
_register_environments()

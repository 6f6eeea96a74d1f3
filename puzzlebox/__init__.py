"""puzzlebox: a MuJoCo digital twin of locking puzzle boxes and the memory-based agents that learn to open them.

One import root. The layers (DESIGN.md) are subpackages: :mod:`puzzlebox.models` (specs, kinds, generators,
MuJoCo models), :mod:`puzzlebox.twin` (the simulated cell), :mod:`puzzlebox.skills` (perception and motion
primitives behind the ``Robot`` seam), :mod:`puzzlebox.learning` (agents, memory, symbolic simulator),
:mod:`puzzlebox.real` (the real xArm-7 driver) and :mod:`puzzlebox.lab` (the composition layer: trials, sweeps,
experiments). Importing ``puzzlebox`` imports none of them; it registers the twin's gymnasium environments
``puzzlebox/TwinPuzzle-v0`` (the option level) and ``puzzlebox/BoxManipulation-v0`` (the low level, the arm at 20 Hz);
the symbolic ``puzzlebox/Puzzle-v0`` is registered by :mod:`puzzlebox.learning`.
"""

__version__ = "0.1.0"


def _register_environments() -> None:
    """``gymnasium.make("puzzlebox/TwinPuzzle-v0", spec=..., config=...)`` and
    ``gymnasium.make("puzzlebox/BoxManipulation-v0", spec=..., obs_mode=..., reward_mode=...)``: registered on
    ``import puzzlebox`` (or ``gymnasium.make("puzzlebox:puzzlebox/...", ...)``), each imported only when made."""
    import gymnasium

    if "puzzlebox/TwinPuzzle-v0" not in gymnasium.registry:
        gymnasium.register(id="puzzlebox/TwinPuzzle-v0", entry_point="puzzlebox.lab.twin_puzzle_env:TwinPuzzleEnv")
    if "puzzlebox/BoxManipulation-v0" not in gymnasium.registry:
        gymnasium.register(
            id="puzzlebox/BoxManipulation-v0", entry_point="puzzlebox.lab.box_manipulation_env:BoxManipulationEnv"
        )


_register_environments()

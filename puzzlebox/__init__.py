"""puzzlebox: a MuJoCo digital twin of locking puzzle boxes and the memory-based agents that learn to open them.

One import root. The layers (DESIGN.md) are subpackages: :mod:`puzzlebox.models` (specs, kinds, generators,
MuJoCo models), :mod:`puzzlebox.twin` (the simulated cell), :mod:`puzzlebox.skills` (perception and motion
primitives behind the ``Robot`` seam), :mod:`puzzlebox.learning` (agents, memory, symbolic simulator),
:mod:`puzzlebox.real` (the real xArm-7 driver) and :mod:`puzzlebox.lab` (the composition layer: trials, sweeps,
experiments). Importing ``puzzlebox`` imports none of them; it registers the twin's gymnasium environment
``puzzlebox/TwinPuzzle-v0`` (the symbolic ``puzzlebox/Puzzle-v0`` is registered by :mod:`puzzlebox.learning`).
"""

__version__ = "0.1.0"


def _register_environments() -> None:
    """``gymnasium.make("puzzlebox/TwinPuzzle-v0", spec=..., config=...)``: registered on ``import puzzlebox`` (or
    ``gymnasium.make("puzzlebox:puzzlebox/TwinPuzzle-v0", ...)``), the environment imported only when made."""
    import gymnasium

    if "puzzlebox/TwinPuzzle-v0" not in gymnasium.registry:
        gymnasium.register(id="puzzlebox/TwinPuzzle-v0", entry_point="puzzlebox.lab.twin_puzzle_env:TwinPuzzleEnv")


_register_environments()

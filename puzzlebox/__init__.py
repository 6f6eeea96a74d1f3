"""puzzlebox: a MuJoCo digital twin of locking puzzle boxes and the memory-based agents that learn to open them.

One import root. The layers (DESIGN.md) are subpackages: :mod:`puzzlebox.models` (specs, kinds, generators,
MuJoCo models), :mod:`puzzlebox.twin` (the simulated cell), :mod:`puzzlebox.skills` (perception and motion
primitives behind the ``Robot`` seam), :mod:`puzzlebox.learning` (agents, memory, symbolic simulator),
:mod:`puzzlebox.real` (the real xArm-7 driver) and :mod:`puzzlebox.lab` (the composition layer: trials, sweeps,
experiments). Importing ``puzzlebox`` imports none of them.
"""

__version__ = "0.1.0"

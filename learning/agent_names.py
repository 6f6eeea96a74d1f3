"""Every agent's name, in one torch-free place: the command line, the protocols, the deep baselines' registry
and their checkpoints all read them here (``tests/learning/test_agent_names.py`` checks each registry against
them)."""

from __future__ import annotations

DEEP_AGENT_NAMES = ("dqn", "model-based", "mt-dqn", "mt-model-based")
"""The deep baselines (torch; ``learning.baselines``): DQN, the precondition planner, and their MT-OPT
variants."""
BELIEF_AGENT_NAMES = ("memory", "dual")
"""The agents that act on a belief over the lock graph (the dual controller's)."""
SYMBOLIC_AGENT_NAMES = ("memory", "dual", "random", "oracle")
"""The agents without a network: they run anywhere, with no checkpoint."""
AGENT_NAMES = (*SYMBOLIC_AGENT_NAMES, *DEEP_AGENT_NAMES)
"""``memory``: dual controller + memory prior (needs a memory); ``dual``: no memory; ``random``;
``oracle``: knows the spec's locks and plays a shortest plan (the floor on actions); the deep
baselines need a checkpoint."""
POSE_ENCODINGS = ("relative", "absolute")
"""Where the deep agents' graph network sees poses (``learning.baselines.GraphNetworkConfig.poses``)."""

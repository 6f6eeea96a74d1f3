"""Memory-based learning: past dependency graphs, keyed by relative pose, recalled as priors."""

from puzzlebox.learning.memory.keys import relative_pose_keys, se3_pose_keys
from puzzlebox.learning.memory.prior import MemoryConfig, episode_record, recall_prior
from puzzlebox.learning.memory.store import MEMORY_FORMAT, SCHEMA_VERSION, MemoryStore

__all__ = [
    "MEMORY_FORMAT",
    "SCHEMA_VERSION",
    "MemoryConfig",
    "MemoryStore",
    "episode_record",
    "recall_prior",
    "relative_pose_keys",
    "se3_pose_keys",
]

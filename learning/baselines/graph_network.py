"""A graph network over puzzle components (Battaglia et al. 2018, "Relational inductive biases"):
GN blocks with edge, node and global updates, on a fully connected graph of the components.

Node features: kind one-hot (over the network's kind family, ``GraphNetworkConfig.kinds``), state
(0/1), goal flag. Edge features (i -> j): the pose of j in i's frame (the memory's relative-pose key,
``learning.memory.keys``: x, y / scale, sin and cos of the relative yaw for planar poses; x, y, z /
scale and sin, cos of relative roll, pitch, yaw for 6-DOF poses), so the network sees what the memory
agent sees. Everything is permutation-equivariant by construction: shuffling the components permutes
the per-node outputs the same way (aggregations are sums and means over nodes). The authors' release
used 5 blocks of 64 hidden units.

A network is built for one kind family and pose size — puzzle boxes (``models.KIND_NAMES``, planar
``[x, y, yaw]``, the default) or disassembly scenes (``DISASSEMBLY_KIND_NAMES``, 6-DOF poses; see
:meth:`GraphNetworkConfig.for_spec`); an observation of another family raises :class:`SceneMismatch`.

``poses="absolute"`` is the ablation closer to the authors' release, whose components carried their
own pose (x, y, sin, cos): the pose goes into the node features instead (position relative to the
components' centroid, over ``position_scale``; yaw in the world frame) and the edge features are zero,
so the network must learn relative geometry itself. It exists for planar poses only.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import torch
from torch import nn

from puzzlebox.learning.agent_names import POSE_ENCODINGS
from puzzlebox.learning.errors import ConfigError, LearningError
from puzzlebox.learning.memory.keys import key_size, relative_pose_keys
from puzzlebox.models import KIND_NAMES, PuzzleSpec, SceneObservation
from puzzlebox.models.disassembly_kinds import (
    DISASSEMBLY_FAMILY,
    DISASSEMBLY_KIND_NAMES,
    DISASSEMBLY_POSE_SIZE,
    PUZZLE_BOX_FAMILY,
    family_kind_names,
)
from puzzlebox.models.kinds import registry_family

NODE_FEATURES = len(KIND_NAMES) + 2
"""Puzzle-box family: kind one-hot, state, goal flag (plus 4 pose features with ``poses="absolute"``);
other families: :attr:`GraphNetworkConfig.node_features`."""
EDGE_FEATURES = 4
"""Puzzle-box family (planar relative-pose keys); other pose sizes: :attr:`GraphNetworkConfig.edge_features`."""
PLANAR_POSE_SIZE = 3
"""A puzzle-box component's pose ``[x, y, yaw]`` [m, m, rad]."""
POSE_SIZES = (PLANAR_POSE_SIZE, DISASSEMBLY_POSE_SIZE)
ABSOLUTE_POSE_FEATURES = 4
"""Node pose features of ``poses="absolute"``: x, y / scale around the centroid, sin and cos of the yaw."""


class SceneMismatch(LearningError, ValueError):
    """An observation (or a scene) of a kind family or pose size the network was not built for; the
    message names the network's kinds and pose size and the scene's."""


def family_name(kinds: Sequence[str]) -> str:
    """``puzzle-box``, ``disassembly``, ``puzzle-box (every registered kind)`` or the kinds themselves for a
    custom tuple (for messages)."""
    names = {  # (the paper's last: with no other kind registered, the registry's kinds are the paper's)
        registry_family().kinds: f"{PUZZLE_BOX_FAMILY} (every registered kind)",
        tuple(DISASSEMBLY_KIND_NAMES): DISASSEMBLY_FAMILY,
        tuple(KIND_NAMES): PUZZLE_BOX_FAMILY,
    }
    return names.get(tuple(kinds), f"kinds {list(kinds)}")


MAX_BLOCKS, MAX_HIDDEN = 64, 4096
"""Bounds of a network's depth (GN blocks) and width (the authors' release: 5 and 64)."""


@dataclass(frozen=True)
class GraphNetworkConfig:
    """Size of the network, and the scenes it is built for (kind family and pose size)."""

    blocks: int = 5
    """GN blocks (the authors' release: 5)."""
    hidden: int = 64
    """Width of every MLP layer and latent (the authors' release: 64)."""
    position_scale: float = 0.02
    """Metres per unit of the pose features' positions (as the memory keys)."""
    poses: str = "relative"
    """Where poses enter: ``relative`` (edge i -> j: pose of j in i's frame) or ``absolute`` (per node)."""
    kinds: tuple[str, ...] = field(default=tuple(KIND_NAMES))
    """The kind family, in one-hot order (default: the puzzle boxes'; checkpoints saved before this
    field existed load with it)."""
    pose_size: int = PLANAR_POSE_SIZE
    """Numbers per component pose: 3 planar ``[x, y, yaw]`` or 6 ``[x, y, z, roll, pitch, yaw]``."""

    def __post_init__(self) -> None:
        object.__setattr__(self, "kinds", tuple(self.kinds))  # a JSON list (checkpoints) -> a tuple
        if self.poses not in POSE_ENCODINGS:
            raise ConfigError(f"unknown pose encoding {self.poses!r}; available: {list(POSE_ENCODINGS)}")
        if self.pose_size not in POSE_SIZES:
            raise ConfigError(f"pose_size must be one of {list(POSE_SIZES)}, got {self.pose_size}")
        if self.poses == "absolute" and self.pose_size != PLANAR_POSE_SIZE:
            raise ConfigError(f"poses='absolute' needs planar poses (pose_size 3), got pose_size {self.pose_size}")
        if not self.kinds or len(set(self.kinds)) != len(self.kinds):
            raise ConfigError(f"kinds must be distinct and non-empty, got {list(self.kinds)}")
        for name, bound in (("blocks", MAX_BLOCKS), ("hidden", MAX_HIDDEN)):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= bound:
                raise ConfigError(f"{name} must be an integer in [1, {bound}], got {value!r}")
        scale = self.position_scale
        if isinstance(scale, bool) or not isinstance(scale, int | float) or not (math.isfinite(scale) and scale > 0):
            raise ConfigError(f"position_scale must be a finite length > 0 [m], got {scale!r}")

    @classmethod
    def for_spec(cls, spec: PuzzleSpec, **overrides: object) -> GraphNetworkConfig:
        """The config for ``spec``'s kind family and pose size (other fields: ``overrides`` or defaults)."""
        pose_size = int(spec.poses_in_world().shape[1])
        return cls(**{"kinds": family_kind_names(spec.kinds), "pose_size": pose_size, **overrides})

    @property
    def family(self) -> str:
        """The kind family's name (``puzzle-box``, ``disassembly``) for messages."""
        return family_name(self.kinds)

    @property
    def state_column(self) -> int:
        """Node-feature column of the component state (0/1)."""
        return len(self.kinds)

    @property
    def goal_column(self) -> int:
        """Node-feature column of the goal flag."""
        return len(self.kinds) + 1

    @property
    def node_features(self) -> int:
        return len(self.kinds) + 2 + (ABSOLUTE_POSE_FEATURES if self.poses == "absolute" else 0)

    @property
    def edge_features(self) -> int:
        return key_size(self.pose_size)

    def check_scene(self, kinds: Sequence[str], pose_size: int) -> None:
        """Raise :class:`SceneMismatch` unless every kind is in the family and the pose size matches."""
        unknown = sorted(set(kinds) - set(self.kinds))
        if unknown or pose_size != self.pose_size:
            raise SceneMismatch(
                f"the graph network was built for the {self.family} family (kinds {list(self.kinds)}, "
                f"pose size {self.pose_size}); this scene has kinds {sorted(set(kinds))} "
                f"(unknown: {unknown}) and pose size {pose_size}"
            )


def observation_tensors(observation: SceneObservation, config: GraphNetworkConfig) -> tuple[np.ndarray, np.ndarray]:
    """Node ``(N, config.node_features)`` and edge ``(N, N, config.edge_features)`` features of an
    observation; :class:`SceneMismatch` for a scene outside the config's family or pose size."""
    n = len(observation)
    poses = np.asarray(observation.poses, dtype=float)
    config.check_scene(observation.kinds, poses.shape[1])
    nodes = np.zeros((n, config.node_features), dtype=np.float32)
    for i, component in enumerate(observation.components):
        nodes[i, config.kinds.index(component.kind)] = 1.0
        nodes[i, config.state_column] = component.state
    nodes[observation.goal_index, config.goal_column] = 1.0
    if config.poses == "absolute":
        xy = (poses[:, :2] - poses[:, :2].mean(axis=0)) / config.position_scale
        nodes[:, config.goal_column + 1 :] = np.column_stack([xy, np.sin(poses[:, 2]), np.cos(poses[:, 2])])
        return nodes, np.zeros((n, n, config.edge_features), dtype=np.float32)
    edges = relative_pose_keys(poses, config.position_scale).astype(np.float32)
    return nodes, edges


def _mlp(inputs: int, hidden: int, outputs: int) -> nn.Sequential:
    return nn.Sequential(nn.Linear(inputs, hidden), nn.ReLU(), nn.Linear(hidden, outputs), nn.LayerNorm(outputs))


class GNBlock(nn.Module):
    """One full GN block: edge update, node update from summed incoming edges, global update.

    The edge MLP's first layer acts on ``[edge, sender, receiver, global]``; it is applied as the sum
    of one linear map per part, so the node and global parts are computed once per node (N) instead of
    once per edge (N^2): the same function, fewer multiplications.
    """

    def __init__(self, node: int, edge: int, glob: int, hidden: int) -> None:
        super().__init__()
        self.edge_in = nn.Linear(edge, hidden)
        self.sender_in = nn.Linear(node, hidden, bias=False)
        self.receiver_in = nn.Linear(node, hidden, bias=False)
        self.global_in = nn.Linear(glob, hidden, bias=False)
        self.edge_out = nn.Sequential(nn.ReLU(), nn.Linear(hidden, hidden), nn.LayerNorm(hidden))
        self.node_mlp = _mlp(node + hidden + glob, hidden, hidden)
        self.global_mlp = _mlp(glob + 2 * hidden, hidden, hidden)

    def forward(
        self, nodes: torch.Tensor, edges: torch.Tensor, glob: torch.Tensor, mask: torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        b, n, _ = nodes.shape
        first = (
            self.edge_in(edges)
            + self.sender_in(nodes)[:, :, None, :]  # i
            + self.receiver_in(nodes)[:, None, :, :]  # j
            + self.global_in(glob)[:, None, None, :]
        )
        new_edges = self.edge_out(first) * mask[..., None]
        incoming = new_edges.sum(dim=1)  # into j from every i
        new_nodes = self.node_mlp(torch.cat([nodes, incoming, glob[:, None, :].expand(b, n, -1)], dim=-1))
        edge_mean = new_edges.sum(dim=(1, 2)) / mask.sum(dim=(1, 2)).clamp(min=1)[:, None]
        new_glob = self.global_mlp(torch.cat([glob, new_nodes.mean(dim=1), edge_mean], dim=-1))
        return new_nodes, new_edges, new_glob


class GraphNetwork(nn.Module):
    """Stacked GN blocks and a per-node head: one output per component (a Q-value or a logit)."""

    def __init__(self, config: GraphNetworkConfig | None = None) -> None:
        super().__init__()
        self.config = config or GraphNetworkConfig()
        h = self.config.hidden
        self.encode_nodes = nn.Linear(self.config.node_features, h)
        self.encode_edges = nn.Linear(self.config.edge_features, h)
        self.blocks = nn.ModuleList(GNBlock(h, h, h, h) for _ in range(self.config.blocks))
        self.head = nn.Sequential(nn.Linear(h, h), nn.ReLU(), nn.Linear(h, 1))

    def forward(self, nodes: torch.Tensor, edges: torch.Tensor) -> torch.Tensor:
        """``nodes`` (B, N, node_features), ``edges`` (B, N, N, edge_features) -> (B, N) outputs."""
        b, n, _ = nodes.shape
        mask = 1.0 - torch.eye(n, dtype=nodes.dtype, device=nodes.device)[None].expand(b, n, n)
        x, e = self.encode_nodes(nodes), self.encode_edges(edges) * mask[..., None]
        u = torch.zeros(b, self.config.hidden, dtype=nodes.dtype, device=nodes.device)
        for block in self.blocks:
            dx, de, du = block(x, e, u, mask)
            x, e, u = x + dx, e + de, u + du  # residual: deep stacks train faster
        return self.head(x).squeeze(-1)

    def evaluate(self, observation: SceneObservation) -> np.ndarray:
        """Per-component outputs for one observation."""
        nodes, edges = observation_tensors(observation, self.config)
        with torch.no_grad():
            return self(torch.from_numpy(nodes)[None], torch.from_numpy(edges)[None])[0].numpy()

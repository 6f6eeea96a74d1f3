"""A graph network over puzzle components (Battaglia et al. 2018, "Relational inductive biases"):
GN blocks with edge, node and global updates, on a fully connected graph of the components.

Node features: kind one-hot, state (0/1), goal flag. Edge features (i -> j): the pose of j in i's frame
(the memory's relative-pose key: x, y / scale, sin and cos of the relative yaw), so the network sees
what the memory agent sees. Everything is permutation-equivariant by construction: shuffling the
components permutes the per-node outputs the same way (aggregations are sums and means over nodes).
The authors' release used 5 blocks of 64 hidden units.

``poses="absolute"`` is the ablation closer to the authors' release, whose components carried their
own pose (x, y, sin, cos): the pose goes into the node features instead (position relative to the
components' centroid, over ``position_scale``; yaw in the world frame) and the edge features are zero,
so the network must learn relative geometry itself.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch
from torch import nn

from learning.agents.factory import POSE_ENCODINGS
from learning.errors import ConfigError
from learning.memory.keys import relative_pose_keys
from models import KIND_NAMES, SceneObservation

NODE_FEATURES = len(KIND_NAMES) + 2
"""Kind one-hot, state, goal flag (plus 4 pose features with ``poses="absolute"``)."""
EDGE_FEATURES = 4


@dataclass(frozen=True)
class GraphNetworkConfig:
    """Size of the network."""

    blocks: int = 5
    """GN blocks (the authors' release: 5)."""
    hidden: int = 64
    """Width of every MLP layer and latent (the authors' release: 64)."""
    position_scale: float = 0.02
    """Metres per unit of the pose features' positions (as the memory keys)."""
    poses: str = "relative"
    """Where poses enter: ``relative`` (edge i -> j: pose of j in i's frame) or ``absolute`` (per node)."""

    def __post_init__(self) -> None:
        if self.poses not in POSE_ENCODINGS:
            raise ConfigError(f"unknown pose encoding {self.poses!r}; available: {list(POSE_ENCODINGS)}")

    @property
    def node_features(self) -> int:
        return NODE_FEATURES + (4 if self.poses == "absolute" else 0)


def observation_tensors(observation: SceneObservation, config: GraphNetworkConfig) -> tuple[np.ndarray, np.ndarray]:
    """Node ``(N, config.node_features)`` and edge ``(N, N, EDGE_FEATURES)`` features of an observation."""
    n = len(observation)
    nodes = np.zeros((n, config.node_features), dtype=np.float32)
    for i, component in enumerate(observation.components):
        nodes[i, KIND_NAMES.index(component.kind)] = 1.0
        nodes[i, len(KIND_NAMES)] = component.state
    nodes[observation.goal_index, len(KIND_NAMES) + 1] = 1.0
    poses = np.asarray(observation.poses, dtype=float)
    if config.poses == "absolute":
        xy = (poses[:, :2] - poses[:, :2].mean(axis=0)) / config.position_scale
        nodes[:, NODE_FEATURES:] = np.column_stack([xy, np.sin(poses[:, 2]), np.cos(poses[:, 2])])
        return nodes, np.zeros((n, n, EDGE_FEATURES), dtype=np.float32)
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
        self.encode_edges = nn.Linear(EDGE_FEATURES, h)
        self.blocks = nn.ModuleList(GNBlock(h, h, h, h) for _ in range(self.config.blocks))
        self.head = nn.Sequential(nn.Linear(h, h), nn.ReLU(), nn.Linear(h, 1))

    def forward(self, nodes: torch.Tensor, edges: torch.Tensor) -> torch.Tensor:
        """``nodes`` (B, N, node_features), ``edges`` (B, N, N, EDGE_FEATURES) -> (B, N) outputs."""
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

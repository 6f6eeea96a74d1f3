"""Checkpoints of the deep baselines: the network's ``state_dict`` (``FILE``) and a JSON beside it
(``FILE.json``) with the agent's name, its resolved config, training progress and package versions,
so a checkpoint can be reloaded — and its result re-run — exactly. The config records the network's
kind family and pose size (``GraphNetworkConfig.kinds``, ``pose_size``); checkpoints saved before those
fields existed are of the puzzle-box family, which their defaults rebuild.
"""

from __future__ import annotations

import json
import pickle
import platform
from dataclasses import asdict
from importlib import metadata
from pathlib import Path

import torch

from puzzlebox.learning.baselines.dqn import DQNAgent, DQNConfig
from puzzlebox.learning.baselines.graph_network import GraphNetworkConfig, SceneMismatch, family_name
from puzzlebox.learning.baselines.model_based import ModelBasedAgent, ModelBasedConfig
from puzzlebox.learning.errors import LearningError
from puzzlebox.models import PuzzleSpec
from puzzlebox.models.atomic import write_atomically, write_text_atomically
from puzzlebox.models.disassembly_kinds import family_kind_names
from puzzlebox.models.json_input import JsonInputError, read_json

CHECKPOINT_FORMAT = "puzzlebox-baseline/2"
"""/2: GN blocks apply the edge MLP's first layer per part (``GNBlock``); MT-OPT flags in the config."""
AGENTS = {
    "dqn": (DQNAgent, DQNConfig),
    "mt-dqn": (DQNAgent, DQNConfig),
    "model-based": (ModelBasedAgent, ModelBasedConfig),
    "mt-model-based": (ModelBasedAgent, ModelBasedConfig),
}


class CheckpointError(LearningError):
    """A checkpoint that cannot be loaded: missing, unreadable, or of another agent or format."""


def _network(agent: DQNAgent | ModelBasedAgent) -> torch.nn.Module:
    return agent.q if isinstance(agent, DQNAgent) else agent.net


def save_checkpoint(agent: DQNAgent | ModelBasedAgent, path: str | Path) -> Path:
    """Write ``path`` (weights) and ``path.json`` (metadata), each atomically."""
    meta = {
        "format": CHECKPOINT_FORMAT,
        "agent": agent.name,
        "config": asdict(agent.config),
        "episodes": agent.episodes,
        "versions": {"python": platform.python_version(), "torch": torch.__version__,
                     "puzzlebox": _version("puzzlebox")},
    }  # fmt: skip
    path = write_atomically(path, lambda tmp: torch.save(_network(agent).state_dict(), tmp))
    write_text_atomically(str(path) + ".json", json.dumps(meta, indent=2))
    return path


def one_line(err: BaseException) -> str:
    return " ".join(str(err).split())[:300]


def load_checkpoint(
    path: str | Path, expected_agent: str | None = None, scene: PuzzleSpec | None = None
) -> DQNAgent | ModelBasedAgent:
    """The agent of a checkpoint, ready to evaluate (``training = False``). With ``scene``, refuse
    (:class:`CheckpointError` naming both families) a network built for another kind family or pose
    size than the scene's, rather than fail on its first observation."""
    path = Path(path)
    meta_path = Path(str(path) + ".json")
    if not path.is_file() or not meta_path.is_file():
        raise CheckpointError(f"no checkpoint at {path} (needs {path.name} and {meta_path.name})")
    try:
        meta = read_json(meta_path)  # bounded in size and depth; NaN refused (a config holds finite numbers)
    except JsonInputError as err:
        raise CheckpointError(f"{meta_path} is not readable JSON: {err}") from None
    if not isinstance(meta, dict) or meta.get("format") != CHECKPOINT_FORMAT or meta.get("agent") not in AGENTS:
        raise CheckpointError(f"{meta_path} is not a puzzlebox baseline checkpoint (agents: {sorted(AGENTS)})")
    if expected_agent is not None and meta["agent"] != expected_agent:
        raise CheckpointError(f"{path} holds agent {meta['agent']!r}, not {expected_agent!r}")
    agent_cls, config_cls = AGENTS[meta["agent"]]
    try:
        raw = dict(meta["config"])
        raw["network"] = GraphNetworkConfig(**raw["network"])
        agent = agent_cls(config_cls(**raw))
    except (KeyError, TypeError, ValueError) as err:
        raise CheckpointError(f"{meta_path} records no valid {meta['agent']} config: {err}") from None
    if scene is not None:
        _check_scene(path, agent.config.network, scene)
    try:
        state = torch.load(path, weights_only=True)
    except (pickle.UnpicklingError, EOFError, RuntimeError, OSError, ValueError) as err:
        raise CheckpointError(f"{path} is not a torch checkpoint ({type(err).__name__})") from None
    try:
        _network(agent).load_state_dict(state)
    except (RuntimeError, TypeError, ValueError, AttributeError) as err:
        raise CheckpointError(f"{path}: weights do not match the recorded config: {one_line(err)}") from None
    episodes = meta.get("episodes", 0)
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 0:
        raise CheckpointError(f"{meta_path}: 'episodes' must be a count >= 0, got {episodes!r}")
    agent.episodes = episodes
    agent.training = False
    return agent


def _check_scene(path: Path, network: GraphNetworkConfig, scene: PuzzleSpec) -> None:
    pose_size = int(scene.poses_in_world().shape[1])
    try:
        network.check_scene(scene.kinds, pose_size)
    except SceneMismatch:
        try:
            scene_family = family_name(family_kind_names(scene.kinds))
        except (ValueError, KeyError):  # mixed or unknown kinds: name them instead
            scene_family = f"kinds {sorted(set(scene.kinds))}"
        raise CheckpointError(
            f"{path} holds a network of the {network.family} family (kinds {list(network.kinds)}, pose size "
            f"{network.pose_size}); scene {scene.name!r} is of the {scene_family} family (kinds "
            f"{sorted(set(scene.kinds))}, pose size {pose_size}): train a network on that family"
        ) from None


def _version(package: str) -> str:
    try:
        return metadata.version(package)
    except metadata.PackageNotFoundError:
        return "not installed"

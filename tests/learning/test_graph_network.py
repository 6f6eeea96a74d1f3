"""The graph network is permutation-equivariant: shuffling the components permutes its outputs."""

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from puzzlebox.learning import SymbolicWorld  # noqa: E402
from puzzlebox.learning.baselines import GraphNetwork, GraphNetworkConfig, observation_tensors  # noqa: E402
from puzzlebox.learning.errors import ConfigError  # noqa: E402
from puzzlebox.models.generator import paper_family  # noqa: E402


@pytest.mark.parametrize("poses", ["relative", "absolute"])
def test_shuffling_the_components_permutes_the_outputs(poses):
    torch.manual_seed(0)
    net = GraphNetwork(GraphNetworkConfig(blocks=3, hidden=32, poses=poses))
    spec = paper_family("test")[0]
    a = SymbolicWorld(spec, seed=1).observe()
    b = SymbolicWorld(spec, seed=2).observe()  # the same scene, components in another order
    out_a, out_b = net.evaluate(a), net.evaluate(b)
    # match components between the two orders by their (unique) positions
    order = [int(np.argmin(np.linalg.norm(a.poses[:, :2] - p[:2], axis=1))) for p in b.poses]
    assert sorted(order) == list(range(5))
    np.testing.assert_allclose(out_b, out_a[order], atol=1e-5)
    assert np.ptp(out_a) > 1e-4  # not a constant: the outputs depend on the components


def test_features_hold_kind_state_goal_and_relative_poses():
    spec = paper_family("test")[1]
    observation = SymbolicWorld(spec, seed=0).observe()
    nodes, edges = observation_tensors(observation, GraphNetworkConfig())
    assert nodes.shape == (5, 5) and edges.shape == (5, 5, 4)
    assert nodes[:, :3].sum(axis=1).tolist() == [1.0] * 5
    assert nodes[observation.goal_index, 4] == 1.0 and nodes[:, 4].sum() == 1.0
    np.testing.assert_allclose(np.diagonal(edges[..., 3]), 1.0)  # cos of a zero relative yaw


def test_absolute_poses_go_into_the_nodes_and_unknown_encodings_are_config_errors():
    spec = paper_family("test")[1]
    observation = SymbolicWorld(spec, seed=0).observe()
    config = GraphNetworkConfig(poses="absolute")
    nodes, edges = observation_tensors(observation, config)
    assert nodes.shape == (5, 9) and not edges.any()
    np.testing.assert_allclose(nodes[:, 5:7].mean(axis=0), 0.0, atol=1e-5)  # centred on the components
    np.testing.assert_allclose(nodes[:, 5:7] * config.position_scale, observation.poses[:, :2]
                               - observation.poses[:, :2].mean(axis=0), atol=1e-6)  # fmt: skip
    np.testing.assert_allclose(np.hypot(nodes[:, 7], nodes[:, 8]), 1.0, atol=1e-6)
    with pytest.raises(ConfigError, match="relative"):
        GraphNetworkConfig(poses="polar")


def test_features_are_sized_from_the_registry_for_boxes_with_new_kinds_and_a_paper_network_refuses_them():
    from puzzlebox.learning.baselines.graph_network import SceneMismatch
    from puzzlebox.models.generator import generate_chain
    from puzzlebox.models.kinds import registry_family

    spec = generate_chain(["slide", "lever", "drawer", "wheel"], seed=0)
    config = GraphNetworkConfig.for_spec(spec)
    assert config.kinds == registry_family().kinds  # the registry's order: door, slide, wheel, drawer, lever
    observation = SymbolicWorld(spec, seed=0).observe()
    nodes, _ = observation_tensors(observation, config)
    assert nodes.shape == (4, len(config.kinds) + 2)
    for row, kind in zip(nodes, observation.kinds, strict=True):  # one-hot in the network's own kind order
        assert row[: len(config.kinds)].tolist() == [float(k == kind) for k in config.kinds]
    paper = GraphNetworkConfig()
    with pytest.raises(SceneMismatch, match=r"lever") as err:
        observation_tensors(observation, paper)
    assert "door', 'slide', 'wheel'" in str(err.value)
    # a paper box in a registry-family network: the paper kinds keep their one-hot columns
    paper_observation = SymbolicWorld(paper_family("test")[0], seed=0).observe()
    paper_nodes, _ = observation_tensors(paper_observation, config)
    assert paper_nodes[:, 3:5].sum() == 0.0

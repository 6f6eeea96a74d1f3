"""Every agent's name lives in ``learning.agent_names``: each registry holds exactly those names, and reading them
loads no torch."""

from __future__ import annotations

import subprocess
import sys

import pytest

from puzzlebox.learning.agent_names import AGENT_NAMES, DEEP_AGENT_NAMES, SYMBOLIC_AGENT_NAMES
from puzzlebox.learning.errors import ConfigError, UnknownAgent
from puzzlebox.learning.experiments.protocol import ProtocolConfig, agent_factory
from puzzlebox.learning.memory.store import MemoryStore
from puzzlebox.models.generator import generate_chain


def test_the_names_are_read_without_torch():
    probe = "import sys, learning.agent_names, learning.agents; assert 'torch' not in sys.modules, 'torch loaded'"
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


def test_the_deep_registry_and_the_checkpoints_know_exactly_the_deep_names():
    pytest.importorskip("torch")
    from puzzlebox.learning.baselines.checkpoint import AGENTS
    from puzzlebox.learning.baselines.registry import LEARNERS

    assert set(LEARNERS) == set(AGENTS) == set(DEEP_AGENT_NAMES)


def test_the_protocols_build_every_symbolic_agent_and_refuse_the_others():
    spec = generate_chain(["door", "slide"], seed=0)
    for name in SYMBOLIC_AGENT_NAMES:
        assert agent_factory(name, MemoryStore(), ProtocolConfig())(spec).name == name
    with pytest.raises(ConfigError, match="unknown agent .dqn. for the symbolic protocols"):
        agent_factory("dqn", None, ProtocolConfig())


def test_an_unknown_agent_lists_every_name():
    from puzzlebox.learning import make_agent

    with pytest.raises(UnknownAgent) as raised:
        make_agent("genius", generate_chain(["door", "slide"], seed=0))
    assert all(name in str(raised.value) for name in AGENT_NAMES)

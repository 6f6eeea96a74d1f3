"""An agent class of one's own, named ``package.module:Class``: loaded when it satisfies the Agent protocol,
refused with what is missing when it does not."""

from __future__ import annotations

import pytest

from puzzlebox.lab.agent_class import load_agent_class, make_agent_object
from puzzlebox.lab.errors import AgentClassError


def test_a_class_with_the_agent_methods_loads_and_is_named():
    agent = make_agent_object("puzzlebox.learning:RandomAgent")
    assert type(agent).__name__ == "RandomAgent" and isinstance(agent.name, str)


@pytest.mark.parametrize(
    ("name", "says"),
    [
        ("no_such_module_here:Agent", "cannot import module 'no_such_module_here'"),
        ("puzzlebox.learning:NoSuchAgent", "has no 'NoSuchAgent'; its classes: ["),
        ("puzzlebox.learning:run_episode", "is not a class"),
        ("puzzlebox.models:PuzzleSpec", "no method begin_episode, choose, record, end_episode"),
        (":Agent", "package.module:Class"),
    ],
)
def test_what_is_not_an_agent_class_is_refused_saying_why(name, says):
    with pytest.raises(AgentClassError) as error:
        load_agent_class(name)
    assert says in str(error.value)


def test_a_class_that_needs_arguments_is_refused():
    with pytest.raises(AgentClassError, match="constructible with no argument"):
        load_agent_class("puzzlebox.learning:OracleAgent")  # it needs the spec

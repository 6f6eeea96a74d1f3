"""One-part boxes: a single free component of a kind, its opening the goal, standing within the robot's reach."""

from __future__ import annotations

import pytest

from puzzlebox.models import LockTable
from puzzlebox.models.errors import GeneratorError
from puzzlebox.models.generator import single_part
from puzzlebox.models.kinds import registered_kinds
from puzzlebox.models.reach import unreachable_handles


@pytest.mark.parametrize("kind", registered_kinds())
def test_a_one_part_box_of_each_kind_is_free_reachable_and_solved_by_opening_it(kind):
    spec = single_part(kind)
    assert [c.kind for c in spec.components] == [kind] and not spec.locks and spec.name == f"single-{kind}"
    assert spec.goal.component == spec.components[0].name and spec.goal.state == 1
    assert spec.box is not None and spec.box.pose is not None and not unreachable_handles(spec, spec.box.pose)
    assert LockTable.from_spec(spec).shortest_solution() == [0]
    assert single_part(kind) == spec  # a pure function of its arguments


def test_an_unknown_kind_is_refused_naming_the_registered_ones():
    with pytest.raises(GeneratorError, match="trapdoor") as err:
        single_part("trapdoor")
    assert all(kind in str(err.value) for kind in registered_kinds())

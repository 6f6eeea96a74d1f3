"""The suite's order and tiers (:mod:`_schedule`): the longest work first, the costly units marked ``slow``."""

from _schedule import GROUPED, SLOW_FROM_S, order_longest_first


class _Item:
    def __init__(self, nodeid: str) -> None:
        self.nodeid, self.marks = nodeid, []

    def add_marker(self, mark) -> None:
        self.marks.append(mark.name)


def test_costly_tests_and_every_test_of_a_costly_grouped_module_are_slow_and_come_first():
    grouped = GROUPED[0]
    items = [_Item("tests/a.py::quick"), _Item("tests/a.py::long"), _Item(f"{grouped}::first"),
             _Item(f"{grouped}::second")]  # fmt: skip
    costs = {"tests/a.py::long": SLOW_FROM_S + 1.0, f"{grouped}::first": SLOW_FROM_S, "tests/a.py::quick": 0.5}
    order_longest_first(items, costs)  # (an unlisted test costs 0.1 s)
    assert [i.nodeid.split("::")[1] for i in items] == ["long", "first", "second", "quick"]
    slow = {i.nodeid.split("::")[1] for i in items if "slow" in i.marks}
    assert slow == {"long", "first", "second"}  # the module's fixture is charged to its first test

"""The --plot top view of a spec: a legend that says what its arrows, colours and thick outline mean."""

import matplotlib.pyplot as plt
from matplotlib.colors import to_rgba
from matplotlib.patches import FancyArrowPatch

from puzzlebox.lab.spec_plot import rule_style, spec_figure
from puzzlebox.models.generator import generate_chain, paper_family


def test_the_lock_graph_has_a_legend_of_its_arrow_styles_kinds_goal_and_axes():
    spec = paper_family("test")[1]
    fig = spec_figure(spec)
    ax = fig.axes[0]
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "locker closed keeps locked closed" in texts and "locker open keeps locked open" in texts
    assert f"goal: {spec.goal.component} open" in texts and set(spec.kinds) <= set(texts)
    assert "a part's x axis" in texts
    arrows = [p for p in ax.patches if isinstance(p, FancyArrowPatch)]
    assert len(arrows) == len(spec.locks)
    for arrow, rule in zip(arrows, spec.locks, strict=True):  # drawn in the style the legend gives its states
        colour, _ = rule_style(rule.locker_state, rule.locked_state)
        assert arrow.get_edgecolor() == to_rgba(colour)
    solid = {arrow.get_linestyle() for arrow, r in zip(arrows, spec.locks, strict=True) if r.locker_state == 0}
    dashed = {arrow.get_linestyle() for arrow, r in zip(arrows, spec.locks, strict=True) if r.locker_state == 1}
    assert solid and dashed and not solid & dashed
    plt.close(fig)


def test_a_box_without_locks_says_so():
    spec = generate_chain(["door", "slide"], seed=0)
    spec = type(spec)(spec.name, spec.components, (), spec.goal, spec.box)
    fig = spec_figure(spec)
    assert fig.axes[0].get_legend().get_title().get_text() == "no lock rules"
    plt.close(fig)

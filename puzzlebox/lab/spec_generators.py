"""The spec generators ``generate.py`` offers by name, each described by a dict of its settings (as a dataset's
manifest records them): ``{"generator": "chain", "kinds": [...]}`` (``models.generator.generate_chain``) and
``{"generator": "random", "components": N, "multi_locker": bool, "kinds": "paper"|"all"}``
(``models.generator.generate_random``)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from puzzlebox.lab.inputs import check_seed
from puzzlebox.models import PuzzleSpec
from puzzlebox.models.generator import BoxConfig, RandomGraphConfig, generate_chain, generate_random
from puzzlebox.models.kinds import family_named


def chain_settings(kinds: str) -> dict[str, Any]:
    """The chain generator's settings from a comma-separated list of kinds (``door,slide,wheel``)."""
    return {"generator": "chain", "kinds": [k.strip() for k in kinds.split(",") if k.strip()]}


def random_settings(
    components: int, multi_locker: bool, kinds: str, require_kinds: tuple[str, ...] = ()
) -> dict[str, Any]:
    """The random generator's settings: ``components`` components, some with two lockers if ``multi_locker``, kinds
    from the family ``kinds`` (``models.kinds.family_named``), each of ``require_kinds`` in every box (the key only
    when some are required: the settings of a dataset made before it stay the same)."""
    settings = {"generator": "random", "components": components, "multi_locker": multi_locker, "kinds": kinds}
    return settings | ({"require_kinds": list(require_kinds)} if require_kinds else {})


def generate_spec(settings: Mapping[str, Any], *, seed: int, name: str | None, anywhere: bool) -> PuzzleSpec:
    """The spec the generator of ``settings`` makes with ``seed`` (named ``name``, else after its settings), where
    the robot reaches every handle unless ``anywhere`` (the default pose, for the symbolic simulator)."""
    check_seed(seed)
    if settings["generator"] == "random":
        family = family_named(settings["kinds"])
        config = RandomGraphConfig(settings["components"], multi_locker=settings["multi_locker"], family=family,
                                   required_kinds=tuple(settings.get("require_kinds", ())))  # fmt: skip
        return generate_random(config, seed=seed, name=name, box=BoxConfig(fit_reach=not anywhere))
    return generate_chain(settings["kinds"], seed=seed, name=name, box=BoxConfig(fit_reach=not anywhere))

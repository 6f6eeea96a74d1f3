"""The annotated top view of each box a twin trial or sweep ran, for the top of its report page.

:func:`write_top_views` renders, for every spec whose runs a directory holds and whose file it can still read,
the gallery's annotated top view (:meth:`twin.gallery.Gallery.annotate`: parts labelled, the goal ringed, each lock
feature in its locker's colour, the lock rules in words below) as ``DIR/gallery/<spec>/top-annotated.png``, once
(a later report reuses it). The page links the PNG (``<img src>``, relative to the page), as it links the videos:
the page stays small whatever the number of boxes.

The specs are those the directory was made from: a trial's ``config.json`` lists its spec files; a sweep's names
its sweep file, whose ``specs`` globs or ``generate`` recipe give them again. Symbolic directories get none (no
rendering needed to read them), nor does a spec whose file has gone: the page then shows no picture for it, and
``on_skip`` is told why (``report.py`` prints it: nothing is left out silently).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import imageio.v3 as iio

from puzzlebox.lab.report_html import ResultsDir
from puzzlebox.models import ModelsError, PuzzleSpec, load_spec
from puzzlebox.models.atomic import write_atomically
from puzzlebox.models.names import name_slug
from puzzlebox.twin.errors import TwinError
from puzzlebox.twin.gallery import Gallery
from puzzlebox.twin.rendering import RenderConfig

__all__ = ["GALLERY_DIR", "TOP_VIEW_CONFIG", "directory_specs", "top_view_path", "write_top_views"]

GALLERY_DIR = "gallery"
"""The folder of a trial or sweep directory that holds its boxes' pictures."""
TOP_VIEW_CONFIG = RenderConfig(width=640, height=480)
"""Size of the top view [px] (the legend strip below it adds a line per lock rule)."""


def top_view_path(directory: Path, spec_name: str) -> Path:
    """Where the annotated top view of ``spec_name`` lies in a trial or sweep ``directory``."""
    return Path(directory) / GALLERY_DIR / name_slug(spec_name) / "top-annotated.png"


def _ignore(_: str) -> None:
    pass


def directory_specs(data: ResultsDir, on_skip: Callable[[str], None] = _ignore) -> list[PuzzleSpec]:
    """The specs a twin trial or sweep directory ran, as far as their files can still be read (none for a
    symbolic one); each once, in the order first met. ``on_skip`` is told of each file that cannot be read."""
    config = data.config
    if config.get("command") == "trial" and config.get("sim") == "twin":
        specs = []
        for file in config.get("specs") or []:
            try:
                specs.append(load_spec(file))
            except (ModelsError, OSError, ValueError) as err:
                on_skip(f"no top view of {file}: {err}")
    elif config.get("command") == "sweep" and isinstance(config.get("sweep"), dict):
        sweep = config["sweep"]
        if sweep.get("sim") != "twin":
            return []
        from puzzlebox.lab.sweep_grid import SweepError, sweep_specs

        try:
            specs = sweep_specs(sweep, Path(str(config.get("sweep_file", "."))).parent)
        except (SweepError, ModelsError, OSError, ValueError) as err:
            on_skip(f"no top views: the sweep's specs cannot be read again ({err})")
            return []
    else:
        return []
    ran = {str(record.get("spec")) for _, record in data.runs}
    unique = {spec.name: spec for spec in reversed(specs) if spec.name in ran}
    return [unique[name] for name in dict.fromkeys(s.name for s in specs) if name in unique]


def write_top_views(data: ResultsDir, on_skip: Callable[[str], None] = _ignore) -> dict[str, Path]:
    """Spec name -> its annotated top view in ``data``'s directory, rendered now if it is not there yet (see the
    module docstring). A box that cannot be drawn (no OpenGL here) has no entry; ``on_skip`` is told why."""
    out: dict[str, Path] = {}
    for spec in directory_specs(data, on_skip):
        path = top_view_path(data.path, spec.name)
        if not path.is_file():
            try:
                with Gallery(spec, TOP_VIEW_CONFIG) as gallery:
                    view = gallery.top_view()
                    image = gallery.annotate(view, gallery.render(view))
            except (TwinError, ModelsError) as err:
                on_skip(f"no top view of {spec.name}: {err}")
                continue
            path.parent.mkdir(parents=True, exist_ok=True)
            write_atomically(path, lambda tmp, image=image: iio.imwrite(tmp, image, extension=".png"))
        out[spec.name] = path
    return out

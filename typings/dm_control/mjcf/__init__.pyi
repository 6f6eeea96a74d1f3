"""Partial type stubs for ``dm_control.mjcf`` (PyMJCF), for pyright (pyproject's ``stubPath``).

PyMJCF's elements are dynamic: an element's children and MJCF attributes are looked up from the MJCF schema
by ``__getattr__`` (``root.worldbody``, ``geom.pos``), and pyright infers for every one of them the union of
all that ``__getattr__`` can return (a list view, an element, None, an attribute value). Here they are
``Any``, as is anything else of the module; the methods this project calls keep their types.
"""

from typing import Any

class Asset:
    def __init__(self, contents: bytes | str, extension: str, prefix: str = "") -> None: ...

class Element:
    def find(self, namespace: str, identifier: str) -> Element | None: ...
    def find_all(
        self, namespace: str, immediate_children_only: bool = False, exclude_attachments: bool = False
    ) -> list[Element]: ...
    def add(self, element_name: str, **kwargs: Any) -> Element: ...
    def remove(self, affect_attachments: bool = False) -> None: ...
    def all_children(self) -> list[Element]: ...
    def attach(self, attachment: RootElement) -> Element: ...
    def to_xml_string(
        self,
        prefix_root: Any = None,
        self_only: bool = False,
        pretty_print: bool = True,
        debug_context: Any = None,
        *,
        precision: int = ...,
        zero_threshold: float = ...,
        filename_with_hash: bool = True,
    ) -> str: ...
    def __getattr__(self, name: str) -> Any: ...
    def __setattr__(self, name: str, value: Any) -> None: ...

class RootElement(Element):
    def __init__(self, model: str | None = None, model_dir: str = "", assets: dict[str, Any] | None = None) -> None: ...
    def get_assets(self) -> dict[str, bytes]: ...

def from_xml_string(
    xml_string: str,
    escape_separators: bool = False,
    model_dir: str = "",
    resolve_references: bool = True,
    assets: dict[str, Any] | None = None,
) -> RootElement: ...
def from_path(
    path: str, escape_separators: bool = False, resolve_references: bool = True, assets: dict[str, Any] | None = None
) -> RootElement: ...
def __getattr__(name: str) -> Any: ...

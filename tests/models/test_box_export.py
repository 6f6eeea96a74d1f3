"""The box alone (models.box_export): the model exported is the model checked, and only a box builds as one."""

import mujoco
import pytest

from puzzlebox.models import spec_from_dict
from puzzlebox.models.box_export import NotAPuzzleBox, build_box_model, compile_box, export_box
from puzzlebox.models.generator import paper_family
from puzzlebox.models.lock_check import check_locks


def test_the_exported_box_is_the_compiled_box_and_holds_its_rules_by_contact(tmp_path):
    spec = paper_family("test")[0]
    path = export_box(spec, tmp_path)
    assert path == tmp_path / "box.xml" and not list(tmp_path.glob(".*.tmp"))  # no temporary left behind
    loaded = mujoco.MjModel.from_xml_path(str(path))
    model, joints = compile_box(spec)
    assert (loaded.nbody, loaded.ngeom, loaded.njnt, loaded.neq) == (model.nbody, model.ngeom, model.njnt, model.neq)
    assert set(joints) == {c.name for c in spec.components}
    lid = model.body("lid")
    assert model.body_pos[lid.id].tolist() == [0, 0, 0]  # the lid frame is the world frame
    check = check_locks(spec, model, joints)
    assert check.agreeing == len(check.transitions) == 30


def test_a_disassembly_scene_is_not_a_box(scene_dict):
    with pytest.raises(NotAPuzzleBox, match="no box"):
        build_box_model(spec_from_dict(scene_dict))


def test_an_unknown_lock_mode_is_refused():
    with pytest.raises(ValueError, match="contact"):
        build_box_model(paper_family("test")[0], locks="glue")

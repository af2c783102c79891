"""The kernel's data contract (softgym/engine/contract.py): one table, and what is derived from it.

The table gives every kernel array and setting and the named codes; ``_batch.pxd``
and ``_bind.pyx`` are rendered from it (softgym/engine/_codegen.py), ``build_layout``
casts and checks the arrays against it.
"""

import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from engine_builders import reference_robot

from softgym.engine import SimConfig, Simulation, _bind, _codegen, _core, contract, layout
from softgym.engine.layout import build_layout
from softgym.terrain import Terrain

ENGINE = Path(contract.__file__).resolve().parent
KERNEL_CONSTANTS = {"N_AUX", "FM_STRIDE"}


def test_table_is_consistent():
    names = [a.name for a in contract.ARRAYS]
    assert len(names) == len(set(names))
    assert contract.KERNEL_ARRAYS == tuple(names)
    settings = [s.name for s in contract.SETTINGS]
    assert len(settings) == len(set(settings)) and not set(settings) & set(names)
    counts = set(contract.COUNTS) | KERNEL_CONSTANTS
    for spec in contract.ARRAYS:
        assert spec.section in contract.SECTIONS, spec.name
        assert spec.ctype in contract.CTYPES, spec.name
        assert spec.doc and not spec.doc.endswith("."), spec.name
        for dim in spec.shape:
            assert isinstance(dim, int) or re.sub(r" \+ \d+$", "", dim) in counts, (spec.name, dim)
        if spec.padded or spec.single or spec.single_only:
            assert spec.section == "link" and spec.shape[1:] == ("n_links",), spec.name
        if spec.single:
            assert spec.dtype == "float64" and spec.single not in names, spec.name
    for s in contract.SETTINGS:
        assert s.ctype in contract.CTYPES and s.doc, s.name
    # the padded rows are the ones the kernel reads with one stride (Batch.link_rows)
    assert {a.name for a in contract.ARRAYS if a.padded} == {"c_seed", "k_seed32", "link_last"}


def test_codes():
    assert contract.MODEL.as_dict() == {"seed": 0, "corotational": 1}
    assert contract.ACTUATION.as_dict() == {"seed": 0, "symmetric": 1}
    assert contract.STATUS.as_dict() == {"ok": 0, "strain": 1, "nonfinite": 2, "memory": 3}
    assert contract.MODEL.cname("corotational") == "MODEL_COROTATIONAL"
    # the kernel's names of its status codes follow the table
    assert sorted(_core.STATUS_NAMES) == sorted(contract.STATUS.as_dict().values())
    for table in (contract.MODEL, contract.ACTUATION, contract.STATUS):
        values = [c.value for c in table.codes]
        assert len(values) == len(set(values))
    with pytest.raises(KeyError, match="model code 'voxelyze' unknown"):
        contract.MODEL["voxelyze"]


@pytest.mark.parametrize(("model", "actuation"), [("seed", "seed"), ("corotational", "symmetric")])
def test_layout_takes_the_codes_from_the_table(model, actuation):
    lay = build_layout([reference_robot(2)], [Terrain.flat()], SimConfig(model=model, actuation=actuation))
    assert lay.settings["model"] == contract.MODEL[model]
    assert lay.settings["actuation_mode"] == contract.ACTUATION[actuation]
    assert sorted(lay.settings) == sorted(s.name for s in contract.SETTINGS)


def test_rendered_files_are_current():
    # the committed _batch.pxd and _bind.pyx are what the contract and templates render
    # (after an edit of contract.py or a .tp: `python softgym/engine/_codegen.py`)
    assert _codegen.generate(check=True) == []


def test_rendered_struct_holds_every_array_and_setting():
    text = (ENGINE / "_batch.pxd").read_text()
    struct = text.split("cdef struct Batch:")[1].split("\n\n\n")[0]
    fields = {name: ctype for ctype, name in re.findall(r"^    ([\w]+\*?) (\w+)\s", struct, re.M)}
    for spec in contract.ARRAYS:
        assert fields[spec.name] == spec.ctype + "*", spec.name
        if spec.single:
            assert fields[spec.single] == "float*"
    for s in contract.SETTINGS:
        assert fields[s.name] == s.ctype, s.name
    for table in (contract.MODEL, contract.ACTUATION, contract.STATUS):
        for code in table.codes:
            assert re.search(rf"^    {table.cname(code.name)} = {code.value}\b", text, re.M)
    bind = (ENGINE / "_bind.pyx").read_text()
    for spec in contract.ARRAYS:
        assert f'b.{spec.name} = <{spec.ctype}*> ' in bind, spec.name


def test_codegen_command_checks_and_renders(tmp_path):
    # the documented command, and setup.py's way in: the file alone, without the package
    res = subprocess.run([sys.executable, str(ENGINE / "_codegen.py"), "--check"],
                         capture_output=True, text=True, cwd=tmp_path)  # fmt: skip
    assert res.returncode == 0, res.stdout + res.stderr
    spec = importlib.util.spec_from_file_location("contract_alone", ENGINE / "contract.py")
    alone = importlib.util.module_from_spec(spec)
    sys.modules["contract_alone"] = alone
    try:
        spec.loader.exec_module(alone)
    finally:
        del sys.modules["contract_alone"]
    assert alone.KERNEL_ARRAYS == contract.KERNEL_ARRAYS
    # stdlib only: nothing of numpy or the compiled engine at import
    code = (f"import sys; sys.path.insert(0, {str(ENGINE)!r}); import contract; "
            "assert not [m for m in sys.modules if m.split('.')[0] in ('numpy', 'softgym')]")
    assert subprocess.run([sys.executable, "-c", code], cwd=tmp_path).returncode == 0


def test_stale_rendering_is_reported(tmp_path, monkeypatch):
    # a rendered file that lags the table is named (and rewritten unless checking)
    for name in ("contract.py", "_codegen.py", *_codegen.TEMPLATES):
        (tmp_path / name).write_text((ENGINE / name).read_text())
    monkeypatch.setattr(_codegen, "HERE", tmp_path)
    assert {p.name for p in _codegen.generate(check=True)} == {"_batch.pxd", "_bind.pyx"}
    assert {p.name for p in _codegen.generate()} == {"_batch.pxd", "_bind.pyx"}
    assert _codegen.generate(check=True) == []
    assert (tmp_path / "_batch.pxd").read_text() == (ENGINE / "_batch.pxd").read_text()


@pytest.mark.parametrize("precision", ["single", "double"])
def test_layout_meets_the_table(precision):
    cfg = SimConfig(self_collision=True, link_precision=precision)
    terrain = Terrain.fence(inner=10, height=1, thickness=1, center=(3, 3))
    lay = build_layout([reference_robot(3), reference_robot(2)], [terrain, Terrain.flat()], cfg)
    a = lay.arrays
    counts = {**contract.counts_of(a, lay.settings), "N_AUX": len(_core.AUX_NAMES),
              "FM_STRIDE": _core.FM_STRIDE}
    contract.check_arrays(a, counts)
    assert counts["n_obs"] > 0 and counts["n_links"] > 0
    f32 = precision == "single"
    assert a["link_last"].dtype == (np.float32 if f32 else np.float64)
    assert a["k_seed32"].shape == (11, counts["n_links"] if f32 else 0)
    for spec in contract.ARRAYS:
        if spec.padded and a[spec.name].size:
            n = a[spec.name].shape[1]
            assert a[spec.name].strides[0] == _bind.row_stride(n) * a[spec.name].itemsize


def _with(monkeypatch, name, change):
    # build_layout with the terrain arrays' `name` changed by `change`
    real = layout._terrain_arrays

    def patched(terrains, cfg):
        out = real(terrains, cfg)
        out[name] = change(out[name])
        return out

    monkeypatch.setattr(layout, "_terrain_arrays", patched)
    terrain = Terrain.fence(inner=10, height=1, thickness=1, center=(3, 3))
    return build_layout([reference_robot(2)], [terrain], SimConfig())


def test_layout_casts_to_the_table(monkeypatch):
    lay = _with(monkeypatch, "floor", lambda x: x.astype(bool))
    assert lay.arrays["floor"].dtype == np.int8


def test_layout_refuses_a_wrong_dtype_naming_the_array(monkeypatch):
    with pytest.raises(RuntimeError, match="'floor' has dtype float64.*int8"):
        _with(monkeypatch, "floor", lambda x: x.astype(np.float64))


@pytest.mark.parametrize(("name", "change", "message"), [
    ("obs", lambda x: x.reshape(-1, 2), r"'obs' has shape \(\d+, 2\), expected \(\d+, 4\)"),
    ("obs_rank", lambda x: x[1:], r"'obs_rank' has shape \(\d+,\), expected"),
])  # fmt: skip
def test_layout_refuses_a_wrong_shape_naming_the_array(monkeypatch, name, change, message):
    with pytest.raises(RuntimeError, match=message):
        _with(monkeypatch, name, change)


def test_check_arrays_names_a_missing_array():
    lay = build_layout([reference_robot(2)], [Terrain.flat()], SimConfig())
    a = dict(lay.arrays)
    del a["mu_k"]
    with pytest.raises(ValueError, match=r"\['mu_k'\] missing"):
        contract.check_arrays(a, {})


def test_simulation_runs_the_contracts_arrays():
    sim = Simulation([reference_robot(2)], SimConfig())
    assert set(contract.KERNEL_ARRAYS) <= set(sim._a)
    # a state array is a kernel array, shown in states in its own dtype or _STATE_DTYPE's
    from softgym.engine import simulation

    assert set(simulation._STATE) <= set(contract.KERNEL_ARRAYS)
    assert set(simulation._STATE_DTYPE) <= set(contract.KERNEL_ARRAYS)

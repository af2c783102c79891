"""Hostile .vxa files: a design or an InvalidDesignError, never another exception or a huge allocation."""

import re

import pytest
from fuzzing import FUZZ, outcome  # tests/fuzzing.py
from hypothesis import given
from hypothesis import strategies as st

from softgym.design import MAX_GRID_DIM, default_walker, from_vxa, load_vxa, to_vxa
from softgym.exceptions import DesignFileError, InvalidDesignError

VXA = to_vxa(default_walker())
LEAVES = sorted(set(re.findall(r"<(\w+)>[^<>]*</\1>", VXA)))


def _set(tag, text, source=VXA):
    # a function replacement: the fuzzed text is data, not a pattern (no group references)
    return re.sub(rf"<{tag}>[^<>]*</{tag}>", lambda _: f"<{tag}>{text}</{tag}>", source, count=1)


# ------------------------------------------------------------------ reproducers of issue 12


@pytest.mark.parametrize(
    "text, needle",
    [
        (
            _set("X_Voxels", "100000", _set("Y_Voxels", "100000")),
            f"each side must lie in 1..{MAX_GRID_DIM}",
        ),
        (_set("X_Voxels", "1000", _set("Y_Voxels", "1000")), "more than the cap of 1000000"),
        (_set("X_Voxels", "1e300"), "must be a positive integer"),
        (_set("X_Voxels", "6.5"), "must be a positive integer"),
        (_set("X_Voxels", "6.0"), "must be a positive integer"),
        (_set("X_Voxels", "0"), "each side must lie in"),
        (_set("X_Voxels", "nan"), "is not finite"),
        (_set("CTE", "10"), "cte must lie in"),
        ("\ud800<VXA/>", "cannot be encoded"),
        (b"<?xml version='1.0' encoding='nope'?><VXA/>", "malformed VXA XML"),
        (
            b"<!DOCTYPE x [<!ENTITY e SYSTEM 'file:///etc/passwd'>]><VXA>&e;</VXA>",
            "malformed VXA XML",
        ),
        (None, "must be str or bytes"),
    ],
)
def test_issue12_vxa_reproducers_raise_typed_errors(text, needle):
    with pytest.raises(InvalidDesignError) as exc:
        from_vxa(text)
    assert needle in str(exc.value)


def test_unreadable_vxa_files_raise_design_file_errors(tmp_path):
    for path in (tmp_path / "missing.vxa", tmp_path):
        with pytest.raises(DesignFileError, match=str(path)):
            load_vxa(path)
    bad = tmp_path / "bad.vxa"
    bad.write_bytes(b"\x00\x01 not xml")
    with pytest.raises(InvalidDesignError, match="bad.vxa"):
        load_vxa(bad)


# ------------------------------------------------------------------ properties

TEXTS = (
    st.text(max_size=12)
    | st.sampled_from(["0", "-1", "1e9", "7", "1000", "100000", "inf", "-0", "0x10", " 3 ", "²"])
    | st.integers(-5, 2000).map(str)
    | st.floats().map(repr)
)


@FUZZ
@given(st.lists(st.tuples(st.sampled_from(LEAVES), TEXTS), min_size=1, max_size=3))
def test_mutated_vxa_elements_give_a_design_or_a_typed_error(changes):
    text = VXA
    for tag, value in changes:
        text = _set(tag, value.replace("<", "").replace("&", ""), text)
    label = outcome("vxa: mutated element text", from_vxa, text)
    if label == "valid":
        design = from_vxa(text)
        assert max(design.shape) <= MAX_GRID_DIM


@FUZZ
@given(st.integers(0, len(VXA)), st.integers(0, 40), st.text(max_size=40) | st.binary(max_size=40))
def test_spliced_vxa_text_gives_a_design_or_a_typed_error(at, cut, junk):
    if isinstance(junk, bytes):
        text = VXA.encode("latin-1")
        text = text[:at] + junk + text[at + cut :]
    else:
        text = VXA[:at] + junk + VXA[at + cut :]
    outcome("vxa: spliced text/bytes", from_vxa, text)

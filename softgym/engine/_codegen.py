"""Render the engine's generated Cython from the kernel's contract (``contract.py``).

``_batch.pxd`` (the ``Batch`` struct's array and setting fields, the named codes'
``cdef enum`` s) and ``_bind.pyx`` (``bind``) are rendered from the Tempita templates
``_batch.pxd.tp`` and ``_bind.pyx.tp`` beside this file, as scikit-learn renders its
``.pyx.tp`` files; everything else in them (the scratch pointers and their strides, the
inline accessors, the comments on layout) is hand-written in the templates.
``setup.py`` runs :func:`generate` before it compiles; the rendered files are
committed too (they are what a reader of the kernel reads), and
``tests/engine/test_contract.py`` fails when one is out of date. To render them
without a build::

    python softgym/engine/_codegen.py           # rewrite the files that changed
    python softgym/engine/_codegen.py --check   # exit 1 if one is out of date

Standard library and Cython only: ``setup.py`` loads this file (and ``contract.py``)
from its path before the package is built.
"""

from __future__ import annotations

import importlib.util
import sys
import textwrap
from pathlib import Path

__all__ = ["TEMPLATES", "generate", "main", "render"]

HERE = Path(__file__).resolve().parent

#: The templates, each rendered to its name without ``.tp`` beside it.
TEMPLATES: tuple[str, ...] = ("_batch.pxd.tp", "_bind.pyx.tp")

# the column of a field's comment and the width of a rendered line
_COL = 29
_WIDTH = 99


def _contract():
    # contract.py from its file (the package need not be importable: setup.py runs this)
    name = "_softgym_engine_contract"
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, HERE / "contract.py")
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module  # (dataclasses look their module up while it runs)
        spec.loader.exec_module(module)
    return sys.modules[name]


def _commented(decl: str, comment: str, indent: str = "    ") -> str:
    # `decl` with `comment` from column _COL, wrapped; continuation lines indented by two
    lead = indent + decl
    lines = textwrap.wrap(comment, width=_WIDTH - _COL - 2, subsequent_indent="  ",
                          break_long_words=False, break_on_hyphens=False)  # fmt: skip
    first = (lead.ljust(_COL) if len(lead) < _COL else lead + " ") + "# " + lines[0]
    return "\n".join([first, *(" " * _COL + "# " + line for line in lines[1:])])


def _shape(spec) -> str:
    dims = [str(d) for d in spec.shape]
    return f"({dims[0]},)" if len(dims) == 1 else f"({', '.join(dims)})"


def _array_fields(c, section: str) -> str:
    # the Batch fields of the section's arrays, each with its shape, units and when NULL
    out = []
    for spec in c.ARRAYS:
        if spec.section != section:
            continue
        comment = _shape(spec) + (", rows link_rows apart," if spec.padded else "")
        comment += f" {spec.doc}"
        if spec.single_only:
            comment += "; link_f32 only (no columns and NULL otherwise)"
        elif spec.nullable:
            comment += "; NULL when empty"
        if spec.single:
            comment += f"; NULL with link_f32 (float32 then, bound to {spec.single})"
        out.append(_commented(f"{spec.ctype}* {spec.name}", comment))
        if spec.single:
            out.append(_commented(f"float* {spec.single}",
                                  f"{spec.name} in float32 with link_f32 (NULL otherwise)"))
    return "\n".join(out)


def _counts(c) -> str:
    # the counts that shapes name, as a comment
    text = "Counts in shapes: " + ", ".join(f"{k} = {v}" for k, v in c.COUNTS.items())
    text += "; N_AUX and SOFTGYM_FM_STRIDE (FM_STRIDE) below."
    return "\n".join(textwrap.wrap(text, width=88, initial_indent="# ", subsequent_indent="# "))


def _setting_fields(c) -> str:
    return "\n".join(_commented(f"{s.ctype} {s.name}", s.doc) for s in c.SETTINGS)


def _enums(c) -> str:
    out = []
    for table in (c.STATUS, c.MODEL, c.ACTUATION):
        out += textwrap.wrap(f"contract.{table.prefix}: {table.doc}",
                             width=_WIDTH, initial_indent="# ", subsequent_indent="# ")
        out.append("cdef enum:")
        for code in table.codes:
            out.append(_commented(f"{table.cname(code.name)} = {code.value}", code.doc))
        out.append("")
    return "\n".join(out).rstrip("\n")


def _bind_settings(c) -> str:
    return "\n".join(f'    b.{s.name} = s["{s.name}"]' for s in c.SETTINGS)


def _bind_arrays(c) -> str:
    # each array's data pointer, cast to its field's type; NULL where the table says so
    out = []
    for spec in c.ARRAYS:
        get = "_data_or_null" if spec.nullable else "_data"
        if spec.single:
            out += [
                "    if b.link_f32:",
                f"        b.{spec.name} = NULL",
                f'        b.{spec.single} = <float*> {get}(a, "{spec.name}")',
                "    else:",
                f'        b.{spec.name} = <{spec.ctype}*> {get}(a, "{spec.name}")',
                f"        b.{spec.single} = NULL",
            ]
        else:
            out.append(f'    b.{spec.name} = <{spec.ctype}*> {get}(a, "{spec.name}")')
    return "\n".join(out)


def render(template: str | Path) -> str:
    """The text of template ``template`` (a name in :data:`TEMPLATES`, or a path) rendered
    from the contract.
    """
    from Cython.Tempita import Template

    path = HERE / template if not Path(template).is_absolute() else Path(template)
    c = _contract()
    head = (f"# GENERATED by softgym/engine/_codegen.py from {path.name} and contract.py: edit "
            f"those, then run\n# `python softgym/engine/_codegen.py` (setup.py runs it too).\n")  # fmt: skip
    text = Template(path.read_text(), name=path.name).substitute(
        counts=_counts(c),
        setting_fields=_setting_fields(c),
        robot_fields=_array_fields(c, "robot"),
        voxel_fields=_array_fields(c, "voxel"),
        link_fields=_array_fields(c, "link"),
        enums=_enums(c),
        bind_settings=_bind_settings(c),
        bind_arrays=_bind_arrays(c),
    )
    return head + text


def generate(check: bool = False) -> list[Path]:
    """Render every template; write the files whose text changed (unless ``check``).

    Returns
    -------
    list of Path
        The rendered files that were out of date (now rewritten, unless ``check``).
    """
    stale = []
    for name in TEMPLATES:
        target = HERE / name[: -len(".tp")]
        text = render(name)
        if not target.exists() or target.read_text() != text:
            stale.append(target)
            if not check:
                # rewritten only when changed: an unchanged contract rebuilds nothing
                target.write_text(text)
    return stale


def main(argv: list[str] | None = None) -> int:
    """Command line: render the files (``--check``: only say which are out of date)."""
    args = sys.argv[1:] if argv is None else argv
    check = "--check" in args
    stale = generate(check=check)
    for path in stale:
        print(f"{'out of date' if check else 'rendered'}: {path.relative_to(HERE.parents[1])}")
    return 1 if check and stale else 0


if __name__ == "__main__":
    raise SystemExit(main())

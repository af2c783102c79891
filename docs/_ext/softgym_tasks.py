"""Sphinx extension: one page per task of the registry (``softgym.tasks.KINDS``).

At ``builder-inited`` it writes ``docs/tasks/index.md`` and ``docs/tasks/<name>.md``
(generated, git-ignored) from each task's registry entry: its summary, family, Gym id,
score, how long ``softgym.evaluate`` and an env episode run it, arguments with their
defaults and ranges, the engine settings it sets, the world it builds around the default
6x6x6 grid, the docstring of its layout function and its sensing observation's layout
(``softgym.tasks.sensing``); the index lists the tasks by family. Run it alone with
``python docs/_ext/softgym_tasks.py OUT_DIR``.
"""

import inspect
import sys
from pathlib import Path

from softgym.envs import SoftWalkerEnv, env_id
from softgym.envs.walker import make_config
from softgym.tasks import ALIASES, FAMILIES, KINDS, get_task, tasks_of_family
from softgym.tasks.sensing import CELL_SENSORS, ROBOT_SENSORS, sensing_layout

SHAPE = (6, 6, 6)


def _fmt(v):
    return f"{v:g}" if isinstance(v, float) else str(v)


def durations(name: str) -> tuple[str, str]:
    """How long ``softgym.evaluate`` and an env episode run task ``name`` by default, in words.

    Read from the code: the task's ``seconds`` and settling time (``SimConfig.init_time``
    as the task sets it), the env's default ``control_dt`` and its episode (the task's
    seconds minus the settling, :func:`softgym.envs.walker.make_batch`).
    """
    task = get_task(name)
    settle = float(task.config().init_time)
    env_settle = float(make_config(None, None, None, task).init_time)
    control_dt = inspect.signature(SoftWalkerEnv).parameters["control_dt"].default
    episode = task.seconds - env_settle
    run = (f"{task.seconds:g} s simulated: {settle:g} s of settling, then {task.seconds - settle:g} s "
           "scored (`seconds=` changes it)")  # fmt: skip
    env = (f"{episode:g} s after {env_settle:g} s of settling: {round(episode / control_dt)} steps "
           f"of {control_dt:g} s (`episode_seconds=`, `control_dt=` change it)")  # fmt: skip
    return run, env


def task_page(name: str) -> str:
    """The Markdown page of one task of the registry."""
    kind = KINDS[name]
    defaults = kind.resolve(None)
    terrain = kind.layout(SHAPE, **defaults)
    task = get_task(name)
    aliases = sorted(a for a, t in ALIASES.items() if t == name)
    run, episode = durations(name)
    lines = [
        f"# {name}",
        "",
        f"{kind.summary[0].upper()}{kind.summary[1:]}.",
        "",
        "| | |",
        "|---|---|",
        f"| family | [{kind.family}](index.md#{kind.family}): {FAMILIES[kind.family]} |",
        f"| Gym id | `{env_id(name)}` (blind), `{env_id(name, sensing=True)}` (sensing) |",
        f"| score (`reward`) | `{kind.reward}` |",
        f"| `softgym evolve` | `--task {name}` |",
        f"| `softgym.evaluate` | `task=\"{name}\"` |",
        f"| `softgym.evaluate` run | {run} |",
        f"| env episode | {episode} |",
    ]
    if aliases:
        lines.append(f"| aliases | {', '.join(f'`{a}`' for a in aliases)} |")
    lines += ["", "## Arguments", ""]
    if kind.options:
        lines += [
            "Given after a colon (`\"{0}:{1}={2}\"`) or as `Task(\"{0}\", options={{...}})`; "
            "a value outside its range raises `InvalidParameterError` naming it.".format(
                name, *next(iter((k, _fmt(o.default)) for k, o in kind.options.items()))
            ),
            "",
            "| argument | default | range | meaning |",
            "|---|---|---|---|",
        ]
        for k, o in kind.options.items():
            kind_ = "integer " if o.integer else ""
            lines.append(
                f"| `{k}` | {_fmt(o.default)} | {kind_}[{o.lo:g}, {o.hi:g}] | {o.doc} |"
            )
    else:
        lines.append("None: the task is fixed.")
    sim = kind.sim(defaults)
    lines += ["", "## The world", ""]
    if sim:
        settings = ", ".join(f"`{k}={v!r}`" for k, v in sim.items())
        lines += [f"Engine settings (`SimConfig` fields) at the defaults: {settings}.", ""]
    lines.append(
        f"Around a {'x'.join(map(str, SHAPE))} grid at the defaults: "
        f"{len(terrain.boxes)} fixed box(es), {len(terrain.objects)} movable object(s), "
        f"{'a floor' if terrain.floor else 'no floor'}."
    )
    doc = inspect.getdoc(kind.layout)
    if doc:
        lines += ["", "The layout function's docstring:", "", "```text", doc, "```"]
    lay = sensing_layout(task, SHAPE)
    lines += [
        "", "## Observation (sensing)", "",
        f"`{env_id(name, sensing=True)}` (or `observe=\"sensing\"`) observes "
        f"{lay.size} values on the {'x'.join(map(str, SHAPE))} grid ({len(CELL_SENSORS)} per "
        f"cell, {len(ROBOT_SENSORS)} of the robot, {lay.n_task} of the task), each clipped "
        "to its bound; `c` is a cell's C-order index, `n` the number of cells. A brain reads "
        "the same values (`softgym.tasks.brains.brain_spec`): a central one all of them, a "
        f"distributed one its cell's, the robot's and the task's ({lay.local_size}) plus its "
        "neighbours' signals.",
        "", "| index | value | bound |", "|---|---|---|",
    ]
    lines += [f"| `{i}` | {what} | {b} |" for i, what, b in lay.table()]
    if not lay.task_senses:
        lines += ["", "The task adds no senses of its own: the robot feels the world through touch."]
    return "\n".join(lines) + "\n"


def index_page() -> str:
    """The tasks' index: a table of the tasks of each family and the toctree of their pages."""
    lines = [
        "# Tasks",
        "",
        f"{len(KINDS)} tasks in {len(FAMILIES)} families. Every task is defined once in "
        "`softgym.tasks` (the registry `softgym.tasks.KINDS`: family, world, engine settings, "
        "measure, difficulty arguments, senses) and runs the same way in `softgym.evaluate`, "
        "its Gym id and `softgym evolve --task NAME` "
        "(`softgym.tasks.tasks_of_family(\"climbing\")` names a family's tasks). These pages "
        "are generated from the registry when the site is built.",
    ]
    for family, what in FAMILIES.items():
        lines += [
            "",
            f"## {family}",
            "",
            f"{what[0].upper()}{what[1:]}.",
            "",
            "| task | Gym id | the world and the goal | score | arguments (default) |",
            "|---|---|---|---|---|",
        ]
        for name in tasks_of_family(family):
            kind = KINDS[name]
            args = ", ".join(f"{k} ({_fmt(o.default)})" for k, o in kind.options.items())
            lines.append(
                f"| [{name}]({name}.md) | `{env_id(name)}` | {kind.summary} | `{kind.reward}` | {args} |"
            )
    lines += [
        "",
        "![The task suite: each task's world around the default walker after settling]"
        "(../figures/task_gallery.png)",
        "",
        "```{toctree}",
        ":hidden:",
        "",
        *KINDS,
        "```",
    ]
    return "\n".join(lines) + "\n"


def write_pages(out: Path) -> list[Path]:
    """Write the index and one page per task into ``out``; return the paths written."""
    out.mkdir(parents=True, exist_ok=True)
    pages = {"index": index_page(), **{n: task_page(n) for n in KINDS}}
    written = []
    for stem, text in pages.items():
        path = out / f"{stem}.md"
        if not path.exists() or path.read_text() != text:  # unchanged pages stay cached
            path.write_text(text)
        written.append(path)
    for stale in set(out.glob("*.md")) - set(written):
        stale.unlink()
    return written


def _on_builder_inited(app):
    write_pages(Path(app.srcdir) / "tasks")


def setup(app):
    """Register the page generator with Sphinx."""
    app.connect("builder-inited", _on_builder_inited)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}


if __name__ == "__main__":
    for p in write_pages(Path(sys.argv[1] if len(sys.argv) > 1 else "docs/tasks")):
        print(p)

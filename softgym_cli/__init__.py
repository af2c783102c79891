"""The ``softgym`` command line: one layer above both :mod:`softgym` and :mod:`evolvers`.

``softgym`` (the library) never imports ``evolvers``; this package drives both.

Subcommands
-----------
simulate
    Simulate the embedded default walker (or a design JSON) and write its
    centre-of-mass trajectory figure and a summary JSON.
evolve
    Run one of the seed study's experiments (native loop, DEAP or pymoo),
    on its task or another (``--task NAME``: any task of softgym.tasks, with
    arguments as ``gap:width=3``, or FILE.json), locally or on Dask, into a
    resumable run folder with log, checkpoints, best designs and figures.
replay
    Re-simulate the best robot of a run folder and render it (figures, GIF, MP4).
compare
    Best fitness per generation of several run folders in one figure (the
    report's Fig. 4); runs of one configuration (seeds) as a median with an
    interquartile band.
experiments
    List the named experiments.
view
    Write a self-contained interactive 3D viewer (HTML) of a run's best robot
    or of a design file.
convert
    Convert a design between JSON and ``.vxa`` (VoxCAD / evosoro).
study
    Run the seed report's scenarios over many seeds, each a resumable run
    folder (seeds in parallel on Dask); ``study report RUNS`` writes the
    claim-by-claim report and its figures.
qd
    Quality-diversity: a MAP-Elites archive (pyribs) of robots over body
    descriptors, a resumable run folder with QD-score and coverage per
    generation and a heatmap; ``qd export RUN`` writes the elites as designs.
poet
    Co-evolution of robots and terrains (Enhanced POET): a resumable run folder
    with terrains, score matrices, admissions, transfers and ANNECS per
    iteration, and figures; ``poet compare RUN...`` plots ANNECS of runs
    (POET against the random-terrain control).
info
    The installed version, the kernel build in use (baseline, x86-64-v3,
    x86-64-v4), the builds installed and whether OpenMP is on.

``--resume`` reads the experiment and settings from the run folder (a folder
that holds no run is an error). Ctrl-C stops within a fraction of a second and
prints the command that resumes. ``-v`` shows log lines (and Dask's), ``-q``
hides progress bars; both go before or after the subcommand. The options of
``qd``, ``poet`` and ``study`` go before or after their default ``run``. Every
flag is checked before a run folder is created. ``--help`` shows every default;
``--version`` the installed version and the kernel build in use.
"""

from softgym_cli.parser import main

__all__ = ["main"]

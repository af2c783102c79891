"""The drivers' registry: every backend name resolves to a Driver, and the CLI offers
exactly the registered choices."""

import pytest

from evolvers.drivers.base import Driver
from evolvers.drivers.pymoo_runner import ALGORITHMS
from evolvers.drivers.registry import BACKENDS, PYMOO_ALGORITHMS, driver_class
from evolvers.evaluation.experiments import SELECTIONS
from softgym.exceptions import InvalidParameterError


@pytest.mark.parametrize("name", list(BACKENDS))
def test_every_backend_is_a_driver(name):
    cls = driver_class(name)
    assert issubclass(cls, Driver) and cls.__name__ == BACKENDS[name].cls


def test_an_unknown_backend_is_refused_naming_the_choices():
    with pytest.raises(InvalidParameterError, match=r"backend must be one of \['native'"):
        driver_class("annealing")


def test_the_cli_reads_its_choices_from_the_registries():
    import argparse

    from softgym_cli.runs import add_evolve_parser

    parser = argparse.ArgumentParser()
    p = add_evolve_parser(parser.add_subparsers())
    choices = {a.dest: a.choices for a in p._actions if a.choices}
    assert list(choices["backend"]) == list(BACKENDS)
    assert list(choices["algorithm"]) == list(PYMOO_ALGORITHMS) == list(ALGORITHMS)
    assert list(choices["selection"]) == list(SELECTIONS)

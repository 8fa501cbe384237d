"""artic.mjcf.errors: the command line tells the user's errors from artic's bugs by type."""

from __future__ import annotations

import argparse

import pytest

from artic.mjcf.errors import ArticError, PlantError, UnsupportedVehicleError, UserError
from artic.mjcf.schema import VehicleFileError
from artic.mjcf.steering import SteeringRangeError
from artic.validation.cli import commands
from artic.validation.logs.runfile import LogError


def test_the_kinds_of_error():
    for cls in (VehicleFileError, LogError, SteeringRangeError, UnsupportedVehicleError):
        assert issubclass(cls, UserError) and issubclass(cls, ValueError)
    assert issubclass(UserError, ArticError) and issubclass(PlantError, ArticError)
    assert issubclass(PlantError, RuntimeError) and not issubclass(PlantError, UserError)
    from artic.plant.plant import PlantError as plants

    assert plants is PlantError


@pytest.mark.parametrize("exc, code, says", [
    (UserError("vehicle.toml: key 'x': give a number"), 2,
     "artic: error: vehicle.toml: key 'x': give a number"),
    (PlantError("diverged at t = 3 s"), 1, "artic: simulation failed: diverged at t = 3 s"),
    (ValueError("operands could not be broadcast"), 3, "this is a bug in artic"),
    (ZeroDivisionError("float division by zero"), 3, "this is a bug in artic"),
])
def test_the_command_line_catches_by_type(monkeypatch, capsys, exc, code, says):
    def fails(args):
        raise exc

    class Parser:  # a command whose work raises exc
        def parse_args(self, argv):
            return argparse.Namespace(func=fails)

    monkeypatch.setattr(commands, "build_parser", Parser)
    assert commands.main(["any"]) == code
    err = capsys.readouterr().err
    assert says in err
    # A bug shows where it happened; the user's error is one line.
    assert ("Traceback" in err) == (code == 3)
    if code != 3:
        assert err.count("\n") == 1

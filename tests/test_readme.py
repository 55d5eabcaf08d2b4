"""The README against the program: what it says about outputs, and every command it shows."""

import pathlib
import re

import moreau
from moreau.cli import build_parser

README = pathlib.Path(moreau.__file__).resolve().parent.parent / "README.md"


def _subparsers():
    (sub,) = [a for a in build_parser()._actions if a.__class__.__name__ == "_SubParsersAction"]
    return sub.choices


def test_every_command_that_takes_force_is_documented_with_it():
    takes = {name for name, p in _subparsers().items()
             if any("--force" in a.option_strings for a in p._actions)}
    assert takes == {"sweep", "atlas", "run", "reproduce"}
    paragraphs = [p for p in re.split(r"\n\s*\n", README.read_text()) if "`--force`" in p]
    documented = {name for name in takes for p in paragraphs
                  if re.search(rf"`moreau\s+{name}`", p)}
    assert documented == takes

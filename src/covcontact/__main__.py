"""``python -m covcontact``: the command line."""

from .cli import entry

entry()

"""``python -m covcontact``: the command line."""

from .cli import main

raise SystemExit(main())

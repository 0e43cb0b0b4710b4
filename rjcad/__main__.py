from rjcad.cli import entry

entry()

"""The fuzz corpus of the CLI: cases (corpus.py) and a forking runner (runner.py)."""

"""The rows of a CSV file as dicts, for the tools beside this module (a module, not a script: nothing to run)."""
import csv
import os
import sys


def read_rows(path):
    """Every row of `path`; a file that cannot be read ends the calling tool with its name and the reason."""
    try:
        with open(path, newline="") as f:
            return list(csv.DictReader(f))
    except OSError as e:
        sys.exit(f"{os.path.splitext(os.path.basename(sys.argv[0]))[0]}: cannot read {path}: {e.strerror}")

"""geomint from Python: the registry's systems, systems defined by their formulas, and the studies of the C++
programs (integrate, convergence, work-precision, modified equations), every loop running in C++.

    import geomint
    pendulum = geomint.system("pendulum")
    run = pendulum.integrate("contact", h=0.05, params={"alpha": 0.2})      # dict of numpy arrays
    duffing = geomint.define_system("duffing", coordinates=1,
                                    L="v1^2/2 - q1^2/2 - b*q1^4/4", herglotz="L - alpha*z",
                                    force=["-alpha*v1"], parameters={"alpha": 0.1, "b": 0.5, "T": 10},
                                    initial_q=["1"], initial_v=["0"])
    duffing.convergence(["la", "contact"])["fitted_order"]
    table = geomint.read_tsv("out/pendulum_contact.tsv")                  # columns and the '#' header

Errors are geomint.InputError (a ValueError) and geomint.NumericalFailure (an ArithmeticError with .step and
.quantity), with the C++ message. geomint.GeomintWarning (a UserWarning, through Python's warnings) flags a result
computed but doubtful: a Herglotz form inconsistent with the force, given at the system's first contact-family
run (define_system(..., strict_herglotz=True) refuses such a system at once instead).
"""

import numpy as _np

from ._geomint import (  # noqa: F401  (the public names)
    GeomintWarning,
    InputError,
    NumericalFailure,
    System,
    compiled_formula_shapes,
    define_system,
    git_revision,
    load_system,
    system,
    systems,
)

__all__ = [
    "GeomintWarning",
    "InputError",
    "NumericalFailure",
    "System",
    "Table",
    "compiled_formula_shapes",
    "define_system",
    "git_revision",
    "load_system",
    "read_tsv",
    "system",
    "systems",
]


class Table(dict):
    """The columns of a geomint TSV file by name (numpy arrays: float where every cell is a number, else str),
    with .meta, the '#' header lines as a dict (program, git, the parameters, ...), and .frame, a pandas
    DataFrame of the columns when pandas is importable (None otherwise)."""

    def __init__(self, columns, meta, frame):
        super().__init__(columns)
        self.meta = meta
        self.frame = frame

    @property
    def columns(self):
        return list(self.keys())


def _column(cells):
    try:
        return _np.array([float(c) for c in cells], dtype=float)
    except ValueError:
        return _np.array(cells, dtype=str)


def read_tsv(path):
    """Reads a TSV file written by a geomint program: '# key: value' header lines, one line of column names,
    then rows of tab-separated cells ('nan', 'inf' are numbers). Returns a Table (a dict of numpy arrays, with
    .meta and .frame). A ragged row is a ValueError naming its line."""
    meta = {}
    names = None
    rows = []
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, start=1):
            line = line.rstrip("\n")
            if names is None and line.startswith("#"):
                key, sep, value = line[1:].strip().partition(":")
                if sep:
                    meta[key.strip()] = value.strip()
                continue
            if names is None:
                names = line.split("\t")
                continue
            if not line:
                continue
            cells = line.split("\t")
            if len(cells) != len(names):
                raise ValueError(f"{path}:{number}: {len(cells)} cells, the header names {len(names)} columns")
            rows.append(cells)
    if names is None:
        raise ValueError(f"{path}: no column names (an empty file, or only '#' lines)")
    columns = {name: _column([r[i] for r in rows]) for i, name in enumerate(names)}
    frame = None
    try:
        import pandas  # optional

        frame = pandas.DataFrame(columns)
    except ImportError:
        pass
    return Table(columns, meta, frame)

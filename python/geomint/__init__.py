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

Formulas may be strings or sympy expressions (define_system), and come back as strings in the names that went in
(q1.., v1.., t, z, the parameters' names; docs/formulas.md, "Names") or, with modified_formulas(...,
as_sympy=True), as sympy expressions in the user's own symbols.

Errors are geomint.InputError (a ValueError) and geomint.NumericalFailure (an ArithmeticError with .step and
.quantity), with the C++ message. geomint.GeomintWarning (a UserWarning, through Python's warnings) flags a result
computed but doubtful: a Herglotz form inconsistent with the force, given at the system's first contact-family
run (define_system(..., strict_herglotz=True) refuses such a system at once instead).
"""

import weakref as _weakref

import numpy as _np

from ._geomint import define_system as _define_system
from ._geomint import (  # noqa: F401  (the public names)
    GeomintWarning,
    InputError,
    NumericalFailure,
    System,
    compiled_formula_shapes,
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


# The sympy symbols a system was defined with (define_system given sympy expressions), for the formulas it returns.
_user_symbols = _weakref.WeakKeyDictionary()


def _sympy():
    try:
        import sympy  # optional: only formulas given or asked as sympy objects need it
    except ImportError as e:  # pragma: no cover (sympy is in the project's package list)
        raise ImportError("geomint: sympy expressions need sympy (Debian: python3-sympy)") from e
    return sympy


def _formula_text(expr, field):
    """The formula language's text of a sympy expression: '^' powers, exact rationals a/b, floats at their shortest
    exact decimal, sin cos tan exp log sqrt atan2 (docs/systems/README.md). Anything else is an InputError naming
    the field."""
    sympy = _sympy()
    from sympy.printing.str import StrPrinter

    allowed = {"sin", "cos", "tan", "exp", "log", "sqrt", "atan2"}

    class Printer(StrPrinter):
        def _atom(self, e):
            plain = e.is_Symbol or (e.is_Integer and e >= 0)
            return self._print(e) if plain else "(%s)" % self._print(e)

        def _print_Pow(self, e, rational=False):
            if e.exp == sympy.Rational(1, 2):
                return "sqrt(%s)" % self._print(e.base)
            return "%s^%s" % (self._atom(e.base), self._atom(e.exp))

        def _print_Float(self, e):
            return "(%r)" % float(e)

        def _print_Rational(self, e):
            return "(%d/%d)" % (e.p, e.q)

        def _print_Exp1(self, e):
            return "exp(1)"

        def _print_Function(self, e):
            name = type(e).__name__
            if name not in allowed:
                raise InputError(f"{field}: the function {name} is not in the formula language "
                                 f"(functions: {' '.join(sorted(allowed))})")
            return "%s(%s)" % (name, ", ".join(self._print(a) for a in e.args))

    if expr.has(sympy.I) or any(isinstance(a, (sympy.Derivative, sympy.Integral)) for a in sympy.preorder_traversal(expr)):
        raise InputError(f"{field}: a formula is real and has no derivative or integral: {expr}")
    for f in expr.atoms(sympy.Function):
        if type(f).__name__ not in allowed:
            raise InputError(f"{field}: the function {type(f).__name__} is not in the formula language "
                             f"(functions: {' '.join(sorted(allowed))})")
    return Printer().doprint(expr)


def _is_sympy(x):
    return hasattr(x, "free_symbols") and hasattr(x, "subs") and not isinstance(x, (str, int, float))


def _formula(x, field, seen):
    if _is_sympy(x):
        seen.update(x.free_symbols)
        return _formula_text(x, field)
    return x


def _formulas(xs, base, seen):
    if xs is None or isinstance(xs, str) or _is_sympy(xs):
        return xs if not _is_sympy(xs) else _formula(xs, base, seen)
    return [_formula(x, base + str(i + 1), seen) for i, x in enumerate(xs)]


def define_system(name, coordinates, L, herglotz=None, force=None, energy=None, constraints=None, holonomic=False,
                  parameters=None, definitions=None, initial_q=None, initial_v=None, description="",
                  strict_herglotz=False, time_transform=None, t0=None, z0=None, exact_q=None, exact_v=None):
    """A system from its formulas: each a string in the formula language (docs/systems/README.md), a number, or a
    sympy expression in the same names (symbols q1.., v1.., t, z, the parameters'), printed to that language.
    The rest as _geomint.define_system says (its docstring, below)."""
    seen = set()
    parameters = dict(parameters or {})
    for k, v in list(parameters.items()):
        if isinstance(v, (tuple, list)) and len(v) == 2:
            parameters[k] = (_formula(v[0], "parameter " + str(k), seen), v[1])
        else:
            parameters[k] = _formula(v, "parameter " + str(k), seen)
    definitions = {k: _formula(v, str(k), seen) for k, v in (definitions or {}).items()}
    s = _define_system(
        name, coordinates, _formula(L, "L", seen), herglotz=_formula(herglotz, "herglotz", seen),
        force=_formulas(force, "F", seen), energy=_formula(energy, "E", seen),
        constraints=_formulas(constraints, "g" if holonomic else "phi", seen), holonomic=holonomic,
        parameters=parameters, definitions=definitions, initial_q=_formulas(initial_q, "q", seen),
        initial_v=_formulas(initial_v, "v", seen), description=description, strict_herglotz=strict_herglotz,
        time_transform=_formula(time_transform, "time_transform", seen), t0=_formula(t0, "t0", seen),
        z0=_formula(z0, "z0", seen), exact_q=_formulas(exact_q, "exact q", seen),
        exact_v=_formulas(exact_v, "exact v", seen))
    if seen:
        _user_symbols[s] = {str(x): x for x in seen}
    return s


define_system.__doc__ += "\n" + (_define_system.__doc__ or "")

_modified_formulas = System.modified_formulas


def _sympy_symbols(system, names, symbols):
    sympy = _sympy()
    table = {n: sympy.Symbol(n) for n in names}
    table.update(_user_symbols.get(system, {}))
    if symbols is not None:
        given = symbols.values() if isinstance(symbols, dict) else symbols
        table.update({str(x): x for x in given})
    return table


def modified_formulas(self, scheme, order=4, budget=60.0, params=None, progress=None, as_sympy=False, symbols=None,
                      on_constraint=False):
    """The modified equation as formulas: {K, K_asked, stopped, seconds, symbols, values, rows, size, chart}, each
    row {quantity, k, text, mathematica, latex}, in the names that went in (docs/formulas.md, "Names"). With
    on_constraint=True (a nonholonomic system) the velocities are quasi-velocities on the constraint, q' = S(q) u + w,
    the rows 'v<i>' the map back and 'chart' says how they were chosen. With
    as_sympy=True each row also has 'sympy', the expression built from the user's own symbols (those of the sympy
    expressions define_system was given, then `symbols`, a dict or list of sympy symbols, then plain
    sympy.Symbol(name) for the rest), and the result 'sympy_symbols' {name: symbol}, so that subs, lambdify and
    latex apply to them."""
    f = _modified_formulas(self, scheme, order=order, budget=budget, params=dict(params or {}),
                           on_constraint=on_constraint, progress=progress)
    if as_sympy:
        _sympy()
        from sympy.parsing.sympy_parser import convert_xor, parse_expr, standard_transformations

        table = _sympy_symbols(self, f["symbols"], symbols)
        for row in f["rows"]:
            row["sympy"] = parse_expr(row["text"], local_dict=dict(table),
                                      transformations=standard_transformations + (convert_xor,))
        f["sympy_symbols"] = table
    return f


modified_formulas.__doc__ += "\n" + (_modified_formulas.__doc__ or "")
System.modified_formulas = modified_formulas

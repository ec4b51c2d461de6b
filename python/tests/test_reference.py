"""docs/programs.md is every program's --help as the build prints it, docs/systems.md the registry as the module gives
it (python/reference.py writes both)."""
import importlib.util
import os

BIN = os.environ.get("GEOMINT_BIN_DIR", "build/experiments")
SRC = os.environ.get("GEOMINT_SOURCE_DIR", ".")


def load_reference():
    spec = importlib.util.spec_from_file_location("reference", os.path.join(SRC, "python", "reference.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def assert_current(doc, expected, stale, what, otherwise):
    """docs/<doc> must equal `expected`; else the failure names what is stale (stale(written) lists it)."""
    with open(os.path.join(SRC, "docs", doc), encoding="utf-8") as f:
        written = f.read()
    if written != expected:
        raise AssertionError(f"docs/{doc} is stale (run `make reference`); {what}: "
                             + (", ".join(stale(written)) or otherwise))


def test_program_reference_is_current():
    reference = load_reference()
    assert_current("programs.md", reference.render(BIN),
                   lambda written: [name for name in reference.programs(BIN) if reference.help_text(BIN, name) not in written],
                   "programs whose --help differs", "none (the list of programs or the header changed)")


def test_systems_reference_is_current():
    import geomint

    reference = load_reference()
    assert_current("systems.md", reference.render_systems(geomint),
                   lambda written: [name for name in geomint.systems() if f"\n## {name}\n" not in written],
                   "systems missing", "none (a parameter, scheme or expectation changed)")

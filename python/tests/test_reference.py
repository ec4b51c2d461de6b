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


def test_program_reference_is_current():
    reference = load_reference()
    with open(os.path.join(SRC, "docs", "programs.md"), encoding="utf-8") as f:
        written = f.read()
    expected = reference.render(BIN)
    if written != expected:
        stale = [name for name in reference.programs(BIN) if reference.help_text(BIN, name) not in written]
        raise AssertionError("docs/programs.md is stale (run `make reference`); programs whose --help differs: "
                             + (", ".join(stale) or "none (the list of programs or the header changed)"))


def test_systems_reference_is_current():
    import geomint

    reference = load_reference()
    with open(os.path.join(SRC, "docs", "systems.md"), encoding="utf-8") as f:
        written = f.read()
    expected = reference.render_systems(geomint)
    if written != expected:
        stale = [name for name in geomint.systems() if f"\n## {name}\n" not in written]
        raise AssertionError("docs/systems.md is stale (run `make reference`); systems missing: "
                             + (", ".join(stale) or "none (a parameter, scheme or expectation changed)"))

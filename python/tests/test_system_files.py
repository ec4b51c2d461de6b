"""System files and formulas from other people, through the Python module: a refusal always has its message and
place, nothing it quotes reaches the user raw (a control byte, a carriage return, a NUL that would cut it), and a
system's per-model values are its own.

Run by ctest with the module's other tests (python/CMakeLists.txt).
"""

import pytest

import geomint

BASE = """[system]
name = t
coordinates = 1
[parameters]
T = {T}  # the horizon{doc}
[dynamics]
L = v1^2/2 - q1^2/2{L}
[initial]
q1 = 1
v1 = 0
"""


def write(tmp_path, name, T="10", doc="", L=""):
    path = tmp_path / name
    path.write_bytes(BASE.format(T=T, doc=doc, L=L).encode("latin-1"))
    return str(path)


def test_latin1_degree_sign_is_refused_with_its_place(tmp_path):
    # A Latin-1 degree sign in a parameter's comment: it loaded, and .parameters raised UnicodeDecodeError.
    path = write(tmp_path, "latin1.geomint", doc=", 30\xb0")
    with pytest.raises(geomint.InputError) as e:
        geomint.load_system(path)
    assert str(e.value) == path + ":5:26: byte 0xb0 is not UTF-8 text: save the file as UTF-8"


def test_bytes_that_are_not_utf8_in_a_key_give_a_message(tmp_path):
    # A key quoted in the refusal was not UTF-8: the message could not be decoded and arrived empty.
    path = tmp_path / "key.geomint"
    path.write_bytes(BASE.format(T="10", doc="", L="").replace("L = ", "\xe9L = ").encode("latin-1"))
    with pytest.raises(geomint.InputError) as e:
        geomint.load_system(str(path))
    assert str(e.value) == str(path) + ":7:1: byte 0xe9 is not UTF-8 text: save the file as UTF-8"


def test_escape_sequence_in_a_file_is_refused_and_not_echoed(tmp_path):
    path = write(tmp_path, "esc.geomint", L=" # \x1b]0;retitled\x07")
    with pytest.raises(geomint.InputError) as e:
        geomint.load_system(path)
    message = str(e.value)
    assert message == path + ":7:23: control character (byte 0x1b): a system file is plain text"
    assert "\x1b" not in message and "\x07" not in message


def test_control_bytes_in_a_path_are_escaped_in_the_message():
    with pytest.raises(geomint.InputError) as e:
        geomint.load_system("/nonexistent/a\x1b[2Jb\rc.geomint")
    assert str(e.value) == "cannot read system file '/nonexistent/a\\x1b[2Jb\\rc.geomint': no such file"


@pytest.mark.parametrize("bad, column, byte", [("v1^2/2\r - q1", 7, "0x0d"), ("v1^2/2\x00 - q1", 7, "0x00")])
def test_control_bytes_in_a_formula_given_in_memory(bad, column, byte):
    # A carriage return stayed raw in the message; a NUL cut the message short.
    with pytest.raises(geomint.InputError) as e:
        geomint.define_system("m", 1, bad, parameters={"T": 10}, initial_q=[1], initial_v=[0])
    assert str(e.value) == "L, column %d: L has a control character or a byte that is not UTF-8 (byte %s)" % (column, byte)


def test_expectations_are_per_system(tmp_path):
    # Two systems of one shape: the second reported the first one's horizon cut (T = 20 for a T = 5 system).
    long_run = geomint.load_system(write(tmp_path, "long.geomint", T="500"))
    short_run = geomint.load_system(write(tmp_path, "short.geomint", T="5"))
    assert short_run.expectations["params"] == {}
    assert long_run.expectations["params"] == {"T": 20.0}
    again = geomint.load_system(write(tmp_path, "long2.geomint", T="500"))
    assert again.expectations["params"] == {"T": 20.0}

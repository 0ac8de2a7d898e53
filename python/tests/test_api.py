"""The module's surface: documented names, type stubs that match the extension, help()."""

import inspect
import pydoc
import re
from pathlib import Path

import proxseg
from proxseg import _proxseg

STUB = Path(proxseg.__file__).with_name("_proxseg.pyi")


def stub_names():
    text = STUB.read_text()
    top = set(re.findall(r"^(?:def|class) (\w+)", text, re.M))
    top |= set(re.findall(r"^(\w+): ", text, re.M))  # module attributes
    members = {}
    for cls, body in re.findall(r"^class (\w+).*?:\n((?:    .*\n|\n)*)", text, re.M):
        members[cls] = set(re.findall(r"def (\w+)", body))
    return top, members


def test_the_stubs_name_exactly_what_the_extension_has():
    top, members = stub_names()
    actual = {n for n in dir(_proxseg) if not n.startswith("__")} | {"__version__"}
    assert "__version__" in top
    assert top == actual
    for cls, names in members.items():
        have = {n for n in dir(getattr(_proxseg, cls))
                if not n.startswith("_") or n in ("__init__", "__len__")}
        # Pickling (Frame) is checked by mypy.stubtest (test_habits.py).
        assert names - {"__getstate__", "__setstate__"} == have, cls


def test_public_names_have_docstrings_with_units():
    for name in proxseg.__all__:
        obj = getattr(proxseg, name)
        if name.startswith("__"):
            continue
        assert inspect.getdoc(obj), name
    assert "metres" in proxseg.segment.__doc__ and "ValueError" in proxseg.segment.__doc__
    assert "metres" in proxseg.Frame.__doc__ and "metres" in proxseg.recognize_object.__doc__
    text = pydoc.render_doc(proxseg.segment, renderer=pydoc.plaintext)
    assert "segment(frame" in text and "overrides" in text


def test_version_and_build_info():
    info = proxseg.build_info()
    assert info["version"] == proxseg.__version__ and re.fullmatch(r"\d+\.\d+\.\d+", info["version"])
    assert "commit" in info

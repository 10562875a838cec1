"""The run options of detect, evaluate and optimise are declared once (app/run_options.hpp,
docs/options.md): the CLI's --help, the Python functions and their stubs, and docs/cli.md must all
agree with that declaration."""

import ast
import re
import subprocess
from pathlib import Path

import pytest

import lidarloop
from lidarloop import _lidarloop

COMMANDS = ["detect", "evaluate", "optimise"]
DOCS = Path(__file__).resolve().parents[2] / "docs" / "cli.md"


def stub_keywords(function):
    """The keyword names of `function` in lidarloop/app.pyi."""
    stub = ast.parse((Path(lidarloop.__file__).parent / "app.pyi").read_text())
    for node in stub.body:
        if isinstance(node, ast.FunctionDef) and node.name == function:
            return [a.arg for a in node.args.args + node.args.kwonlyargs]
    raise AssertionError(f"app.pyi has no {function}")


def bound_keywords(function):
    """The parameters pybind11 declares for `function` (the first line of its docstring)."""
    signature = getattr(_lidarloop, function).__doc__.splitlines()[0]
    return re.findall(r"(?:\(|, )\*?\*?(\w+)(?::|\))", signature)


@pytest.mark.parametrize("command", COMMANDS)
def test_python_signature_is_the_declaration(command):
    declared = [o["keyword"] for o in lidarloop.run_options(command)]
    bound = bound_keywords(command)
    assert bound[-1] == "kwargs", bound  # the run options come as keywords
    assert not set(declared) & set(bound), "a run option is also restated in the binding"
    assert sorted(stub_keywords(command)) == sorted(bound[:-1] + declared)
    doc = getattr(_lidarloop, command).__doc__
    for option in lidarloop.run_options(command):
        assert f"{option['keyword']} ({option['flag']}): {option['help']}" in doc


@pytest.mark.parametrize("command", COMMANDS + ["bench"])
def test_help_lists_every_declared_flag(cli, command):
    text = subprocess.run([str(cli), command, "--help"], check=True, capture_output=True,
                          text=True).stdout
    flat = " ".join(text.split())
    for option in lidarloop.run_options(command):
        assert re.search(rf"(^|\s){re.escape(option['flag'])}\b", text), option["flag"]
        assert " ".join(option["help"].split()) in flat, option["help"]


def test_docs_table_is_the_declaration(cli):
    generated = subprocess.run([str(cli), "dump-config", "--markdown-run-options"], check=True,
                               capture_output=True, text=True).stdout.splitlines()
    lines = DOCS.read_text(encoding="utf-8").splitlines()
    begin = lines.index("<!-- dump-config --markdown-run-options -->")
    end = lines.index("<!-- end dump-config --markdown-run-options -->")
    assert lines[begin + 1:end] == generated
    for command in COMMANDS + ["bench"]:
        for option in lidarloop.run_options(command):
            assert any(row.startswith(f"| `{option['flag']}") for row in generated)


def test_a_keyword_that_is_not_declared_is_a_type_error(tmp_path):
    with pytest.raises(TypeError, match="unexpected keyword argument 'top_kk'"):
        lidarloop.detect(tmp_path, out=tmp_path / "out", top_kk=3)
    with pytest.raises(TypeError, match="top_k must be an int"):
        lidarloop.detect(tmp_path, out=tmp_path / "out", top_k="3")
    # Beyond the option's int, or a list with a non-number: a TypeError naming it too.
    with pytest.raises(TypeError, match=r"top_k must be an int \(32-bit\), got 1099511627776"):
        lidarloop.detect(tmp_path, out=tmp_path / "out", top_k=2**40)
    with pytest.raises(TypeError, match="fixed_thresholds must be a list of numbers"):
        lidarloop.evaluate(tmp_path, out=tmp_path / "out", fixed_thresholds=["a"])


def test_a_bad_value_names_the_keyword_it_came_through(tmp_path):
    # Checked when the keyword is applied, before the dataset is opened: the keyword, then the
    # config's own words.
    top_k = r"^top_k: detection.top_k must be in \[1, 1000\]"
    with pytest.raises(lidarloop.ConfigError, match=top_k):
        lidarloop.detect(tmp_path, out=tmp_path / "out", top_k=0)
    distance = "^distance_m: ground_truth.distance_m must be"
    with pytest.raises(lidarloop.ConfigError, match=distance):
        lidarloop.evaluate(tmp_path, out=tmp_path / "out", distance_m=-3.0)

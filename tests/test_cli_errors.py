"""Failures of the command line are one line on stderr, exit status 2 for usage errors and 1 for failures, no
traceback unless ``--debug`` (issue 18, "Tracebacks and unclear messages"): one test per class."""

from pathlib import Path

import pytest

from fowt_env.cli import main


def _one_line_error(capsys, command: str) -> str:
    err = capsys.readouterr().err
    assert "Traceback" not in err
    last = err.strip().splitlines()[-1]
    assert last.startswith(f"fowt-env {command}: error: "), err
    return last


def _exit_code(argv: list[str]) -> int:
    try:
        return main(argv)
    except SystemExit as exc:  # argparse's usage errors
        return int(exc.code or 0)


def test_output_to_a_missing_folder_is_a_usage_error_found_before_the_work(tmp_path, capsys):
    for argv in (["modes", "--json", "/nonexistent/m.json"],
                 ["simulate", "--duration", "10", "--out", str(tmp_path / "nodir" / "r.npz")]):
        assert _exit_code(argv) == 2
        assert "does not exist" in _one_line_error(capsys, argv[0])
    assert not list(tmp_path.iterdir())


def test_an_unwritable_output_is_a_one_line_failure(tmp_path, capsys, monkeypatch):
    """A read-only target (simulated: the tests may run as root, who can write anywhere)."""
    target = tmp_path / "m.json"

    def refuse(self, *args, **kwargs):
        raise PermissionError(13, "Permission denied", str(self))

    monkeypatch.setattr(Path, "write_text", refuse)
    assert _exit_code(["modes", "--json", str(target)]) == 1
    assert _one_line_error(capsys, "modes").endswith(f"{target}: Permission denied")
    with pytest.raises(PermissionError):  # --debug: the traceback, for a bug report
        main(["--debug", "modes", "--json", str(target)])


def test_a_request_beyond_memory_is_a_one_line_failure(tmp_path, capsys):
    assert _exit_code(["simulate", "--duration", "1e12", "--out", str(tmp_path / "r.npz")]) == 1
    assert "not enough memory" in _one_line_error(capsys, "simulate")


def test_a_diverging_simulation_is_a_one_line_failure_naming_the_effects(tmp_path, capsys):
    argv = ["simulate", "--duration", "10", "--effects", "quadratic_drag=1e9", "--out", str(tmp_path / "r.npz")]
    assert _exit_code(argv) == 1
    assert "diverged" in (line := _one_line_error(capsys, "simulate")) and "quadratic_drag=1e9" in line


@pytest.mark.parametrize("spec", ["quadratic_drag", "quadratic_drag=", "=0.5", "quadratic_drag=0.5,aero_damping"])
def test_effects_without_a_strength_are_a_usage_error(tmp_path, capsys, spec):
    assert _exit_code(["simulate", "--duration", "10", "--effects", spec, "--out", str(tmp_path / "r.npz")]) == 2
    assert "NAME=STRENGTH" in _one_line_error(capsys, "simulate")
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("name", ["adir", "newdir/"])
def test_out_naming_a_directory_is_a_usage_error(tmp_path, capsys, monkeypatch, name):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "adir").mkdir()
    assert _exit_code(["simulate", "--duration", "10", "--out", name]) == 2
    assert "names a directory" in _one_line_error(capsys, "simulate")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["adir"]  # no adir.npz, no newdir.npz


def test_ctrl_c_is_one_line_and_status_130(tmp_path, capsys, monkeypatch):
    import surrogates

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(surrogates, "simulate", interrupted)
    assert _exit_code(["simulate", "--duration", "10", "--out", str(tmp_path / "r.npz")]) == 130
    err = capsys.readouterr().err
    assert err.strip() == "fowt-env simulate: interrupted" and not list(tmp_path.iterdir())

"""`retro check --listing FILE --lcov FILE --html DIR` end to end: the files written, all or none,
never over an input, and one-line errors. The check's code coverage is the Machine's trace of the
hand-worked rows (handworked.machine_coverage, which equals the hand count), set on the check here so
the command's writing is tested whether or not the engines fill it."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest
from handworked import ADDRESSES, DATA, ENTRY, EXPECTED_LISTING_ROWS, ROWS, SOURCE_LINE, expected_lcov, machine_coverage

from retro import cli
from retro.commands import check as check_command
from retro.reports.listing import HEADER


@pytest.fixture
def folder(tmp_path) -> Path:
    copy = tmp_path / "coverage"
    shutil.copytree(DATA, copy)
    return copy


@pytest.fixture
def with_coverage(monkeypatch):
    run = check_command.checks_of

    def checks_with_coverage(args):
        checks = run(args)
        for c in checks:
            c.code_coverage = machine_coverage(c.routine.program, ENTRY, [{"x": x} for x in ROWS], ADDRESSES)
        return checks

    monkeypatch.setattr(check_command, "checks_of", checks_with_coverage)


def snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_the_three_reports_are_written(folder, tmp_path, with_coverage, capsys):
    out = tmp_path / "out"
    code = cli.main(["check", str(folder / "sumto.toml"), "--quiet", "--listing", str(out / "sumto.lst"),
                     "--lcov", str(out / "sumto.info"), "--html", str(out / "html")])
    assert code == 0, capsys.readouterr().err
    listing = (out / "sumto.lst").read_text().splitlines()
    assert [line.split() for line in listing[listing.index(HEADER) + 1:]] == EXPECTED_LISTING_ROWS
    assert (out / "sumto.info").read_text() == expected_lcov(str(folder / "sumto.s"), SOURCE_LINE)
    assert sorted(p.name for p in (out / "html").iterdir()) == ["index.html", "sumto.html"]
    assert "sumto.s:9" in (out / "html" / "sumto.html").read_text()


def test_an_input_is_never_written_over_and_nothing_is_written_then(folder, tmp_path, with_coverage, capsys):
    before = snapshot(folder)
    listing = tmp_path / "sumto.lst"
    code = cli.main(["check", str(folder / "sumto.toml"), "--quiet", "--listing", str(listing),
                     "--lcov", str(folder / "sumto.s")])  # the source the debug file names
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and "sumto.s" in err[0] and "input" in err[0]
    assert not listing.exists()  # all or none
    assert snapshot(folder) == before


def test_without_code_coverage_one_line_and_exit_2(folder, tmp_path, monkeypatch, capsys):
    run = check_command.checks_of

    def checks_without(args):
        checks = run(args)
        for c in checks:
            c.code_coverage = None
        return checks

    monkeypatch.setattr(check_command, "checks_of", checks_without)
    out = tmp_path / "sumto.lst"
    assert cli.main(["check", str(folder / "sumto.toml"), "--quiet", "--listing", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["retro check: no code coverage was recorded for sumto (the compiled engine counts none: use "
                   "--engine batch), so --listing, --lcov and --html cannot be written"]
    assert not out.exists()


def test_the_acme_listing_key_maps_lines(folder, tmp_path, with_coverage, capsys):
    out = tmp_path / "acme.info"
    assert cli.main(["check", str(folder / "sumto_acme.toml"), "--quiet", "--lcov", str(out)]) == 0
    text = out.read_text()
    assert f"SF:{folder / 'sumto_acme.asm'}\n" in text and "DA:3,3\n" in text and "DA:12,0\n" in text


@pytest.mark.parametrize("value, message", [
    ('"missing.lst"', "program.listing"),
    ('"../coverage/sumto.s"', "program.listing: .*not a source map retro reads"),
    ("3", "program.listing"),
])
def test_bad_listing_keys_are_one_line_errors(folder, capsys, value, message):
    spec = folder / "bad.toml"
    spec.write_text((folder / "sumto_acme.toml").read_text().replace('"sumto_acme.lst"', value, 1))
    assert cli.main(["check", str(spec), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert re.search(message, err[0]), err[0]


@pytest.mark.parametrize("option", ["--listing", "--lcov"])
@pytest.mark.parametrize("name", ["sumto.toml", "sumto.prg", "sumto.dbg", "sumto.s", "./sumto.s", "link.s"])
def test_no_report_over_any_input(folder, with_coverage, capsys, option, name):
    """The spec, the program, the debug file and the source it names, also through `./` and a link."""
    (folder / "link.s").symlink_to(folder / "sumto.s")
    before = snapshot(folder)
    target = folder / name if not name.startswith("./") else Path(str(folder) + "/./" + name[2:])
    assert cli.main(["check", str(folder / "sumto.toml"), "--quiet", option, str(target)]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1
    assert snapshot(folder) == before


def test_html_folder_over_an_input_file_is_refused_before_the_run(folder, with_coverage, capsys):
    assert cli.main(["check", str(folder / "sumto.toml"), "--quiet", "--html", str(folder / "sumto.s")]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""  # refused before any case ran
    assert captured.err.strip() == f"retro check: {folder / 'sumto.s'}: is a file, not a folder"

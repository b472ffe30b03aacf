"""``glassbench stage``: set merges into the project's stage and saves it, show prints it, and
every refused value is one line, exit status 2 and an untouched project file."""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import app.main as app_main
from engine import cli
from engine.color import hex_to_linear
from engine.files.project import load_project
from engine.model.design import Stage

JAR = Path(__file__).resolve().parents[1] / "resources" / "jar.glassbench"


@pytest.fixture
def project(tmp_path):
    """A copy of the jar sample, which stands on nothing."""
    return Path(shutil.copy(JAR, tmp_path / "jar.glassbench"))


def test_set_stands_the_bottle_on_a_table_and_show_prints_it(project, capsys):
    assert cli.main(["stage", str(project), "set", "table", "--colour", "#c8a040"]) == 0
    assert "wrote" in capsys.readouterr().out
    design, _ = load_project(project)
    assert design.stage == Stage(kind="table", color=hex_to_linear("#c8a040"))
    assert (project.parent / (project.name + ".bak")).exists(), "saved through the project's own save"
    assert app_main.main(["stage", str(project), "show"]) == 0
    out = capsys.readouterr().out
    assert out.count("\n") == 1 and "table" in out and "#c8a040" in out


def test_set_keeps_what_it_is_not_given_and_reads_the_alias(project, capsys):
    assert cli.main(["stage", str(project), "set", "glossy", "--colour", "#101010", "--gloss", "0.25"]) == 0
    assert cli.main(["stage", str(project), "set", "mirror"]) == 0
    stage = load_project(project)[0].stage
    assert (stage.kind, stage.color, stage.gloss) == ("mirror", hex_to_linear("#101010"), 0.25)
    assert cli.main(["stage", str(project), "set", "Shadow-Catcher"]) == 0
    assert load_project(project)[0].stage.kind == "shadow"
    assert cli.main(["stage", str(project), "set", "none"]) == 0
    capsys.readouterr()
    assert cli.main(["stage", str(project), "show"]) == 0
    assert capsys.readouterr().out == "stage: none (the bottle floats in its environment)\n"


def test_set_raises_a_backdrop_sweep_behind_a_table_and_takes_it_away(project, capsys):
    assert cli.main(["stage", str(project), "set", "table", "--backdrop"]) == 0
    assert load_project(project)[0].stage == Stage(kind="table", backdrop=True)
    assert "with its backdrop sweep" in capsys.readouterr().out
    assert cli.main(["stage", str(project), "set", "glossy", "--gloss", "0.5"]) == 0
    assert load_project(project)[0].stage.draws_backdrop, "kept when not given"
    assert cli.main(["stage", str(project), "set", "glossy", "--no-backdrop"]) == 0
    assert load_project(project)[0].stage == Stage(kind="glossy", gloss=0.5)
    capsys.readouterr()
    assert cli.main(["stage", str(project), "show"]) == 0
    assert "backdrop" not in capsys.readouterr().out


@pytest.mark.parametrize("args, words", [
    (["set", "tabel"], "'tabel' is not one of none, shadow (shadow-catcher), table, glossy, mirror"),
    (["set"], "stage set needs a KIND"),
    (["set", "table", "--colour", "#12345"], "--colour '#12345' is not a colour like"),
    (["set", "table", "--colour", "red"], "is not a colour like"),
    (["set", "glossy", "--gloss", "1.5"], "--gloss = 1.5 is outside 0..1"),
    (["set", "glossy", "--gloss", "-0.1"], "--gloss = -0.1 is outside 0..1"),
    (["set", "glossy", "--gloss", "nan"], "--gloss = nan is outside 0..1"),
    (["set", "table", "--gloss", "0.5"], "--gloss does nothing for the stage 'table'"),
    (["set", "mirror", "--backdrop"], "--backdrop does nothing for the stage 'mirror'"),
    (["set", "shadow", "--backdrop"], "--backdrop does nothing for the stage 'shadow'"),
    (["set", "shadow", "--colour", "#ffffff"], "--colour does nothing for the stage 'shadow'"),
    (["show", "table"], "stage show takes no KIND"),
])
def test_a_refused_stage_is_one_line_exit_2_and_leaves_the_file_untouched(project, capsys, args, words):
    before = project.read_bytes()
    assert cli.main(["stage", str(project)] + args) == 2
    err = capsys.readouterr().err
    assert err.startswith("glassbench stage: error: ") and err.count("\n") == 1 and words in err, err
    assert project.read_bytes() == before and not (project.parent / (project.name + ".bak")).exists()


def test_argument_errors_exit_2_and_a_missing_project_is_named(project, tmp_path, capsys):
    with pytest.raises(SystemExit) as exited:
        cli.main(["stage", str(project), "set", "glossy", "--gloss", "shiny"])
    assert exited.value.code == 2 and "--gloss" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        cli.main(["stage", str(project), "paint", "table"])
    assert "invalid choice: 'paint'" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        cli.main(["stage", str(project), "set", "table", "--backdrop=yes"])
    assert "--backdrop" in capsys.readouterr().err
    assert cli.main(["stage", str(tmp_path / "missing.glassbench"), "show"]) == 2
    assert "missing.glassbench" in capsys.readouterr().err

# SPDX-License-Identifier: MIT
# binocle.design() against `binocle design`: the same ranking for the same input, the same
# files with out=, and the same refusals in the same words (the argument named as Python
# spells it).
import pytest

import binocle
from binocle_files import cli, cli_error, read_json


def ranking_of(candidates):
    """(B, f) of each candidate, best first."""
    return [(c["baseline_mm"], c["focal_length_mm"]) for c in candidates]


@pytest.mark.parametrize("cli_args, kwargs", [
    (["--range", "6000"], {"range": 6000}),
    (["--band", "5000,12000", "--lenses", "4,8,12.5"], {"band": [5000, 12000], "lenses": "4,8,12.5"}),
    (["--range", "12000", "--baselines", "100,150,190", "--predictor", "form_factor", "--inclination-deg", "10"],
     {"range": "12000", "baselines": [100, 150, 190], "predictor": "form_factor", "inclination_deg": 10}),
])
def test_design_ranks_as_the_cli(tmp_path, cli_args, kwargs):
    cli("design", *cli_args, "--out", str(tmp_path / "cli"))
    expected = read_json(str(tmp_path / "cli" / "design.json"))["candidates"]
    ranking = binocle.design(**kwargs)
    assert ranking_of(ranking) == ranking_of(expected)
    assert ranking == expected  # every figure too
    # out=: the same files as --out
    binocle.design(**kwargs, out=tmp_path / "py")
    assert (tmp_path / "py" / "design.csv").read_text() == (tmp_path / "cli" / "design.csv").read_text()
    assert read_json(str(tmp_path / "py" / "design.json")) == read_json(str(tmp_path / "cli" / "design.json"))


@pytest.mark.parametrize("cli_args, kwargs, cli_name, py_name", [
    (["--range", "6000,"], {"range": "6000,"}, "--range 6000,", "range='6000,'"),
    (["--range", "6000", "--lenses", "2.8,x"], {"range": 6000, "lenses": "2.8,x"}, "--lenses 2.8,x", "lenses='2.8,x'"),
    (["--band", "12000,5000"], {"band": "12000,5000"}, "--band 12000,5000", "band='12000,5000'"),
    (["--range", "6000", "--baselines", "1:1000000000:1"], {"range": 6000, "baselines": "1:1000000000:1"},
     "--baselines 1:1000000000:1", "baselines='1:1000000000:1'"),
    (["--range", "6000", "--predictor", "nope"], {"range": 6000, "predictor": "nope"}, "--predictor nope", "predictor='nope'"),
])
def test_design_refuses_bad_input_with_the_cli_words(cli_args, kwargs, cli_name, py_name):
    status, _, err = cli("design", *cli_args, check=False)
    assert status == 2
    message = cli_error(err, "design")
    assert message.startswith(cli_name + ": "), message
    with pytest.raises(binocle.UsageError) as e:
        binocle.design(**kwargs)
    assert str(e.value) == py_name + message[len(cli_name):]


def test_design_needs_a_target_and_refuses_a_folder_of_another_kind(tmp_path):
    with pytest.raises(binocle.UsageError, match=r"^give a target: range='6000' \(mm\) or band='5000,12000'$"):
        binocle.design()
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(binocle.Error) as e:
        binocle.design(range=6000, out=tmp_path)
    assert "holds files Binocle did not write there" in str(e.value) and "notes.txt" in str(e.value)
    assert "binocle.design writes" in str(e.value) and "pass force=True" in str(e.value)
    assert not (tmp_path / "design.json").exists()
    assert binocle.design(range=6000, out=tmp_path, force=True)[0]["rank"] == 1
    assert not (tmp_path / "notes.txt").exists() and (tmp_path / "design.json").exists()


def test_design_arguments_are_read_strictly():
    with pytest.raises(binocle.UsageError, match=r"^simulate_count=0: expected a whole number from 1 to"):
        binocle.design(range=6000, simulate_count=0)
    with pytest.raises(binocle.UsageError, match=r"^pixel_pitch_um='-3': expected a positive number$"):
        binocle.design(range=6000, pixel_pitch_um=-3)
    with pytest.raises(binocle.UsageError, match=r"^range=True: expected a number, not a bool$"):
        binocle.design(range=True)
    with pytest.raises(TypeError):
        binocle.design(6000)  # keywords only

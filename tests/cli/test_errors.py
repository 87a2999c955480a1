"""The error contract of the command line: bad input is one line on stderr and exit code 2.

Every case here once ended in a traceback (or was silently accepted): a negative seed, an
output that is a folder, malformed or hostile JSON, TOML and CSV, and sizes whose work would
exhaust the memory or run for hours. Nothing may be written when the input is refused.
"""

import json

import numpy as np
import pytest

from reflector_opt.calibration._files import write_calibration_csv, write_voltage_log
from reflector_opt.calibration._synthetic import built_units, calibration_data, voltage_log
from reflector_opt.calibration._unit_calibration import calibrate_csv, save_calibrations
from reflector_opt.cli import main
from reflector_opt.design import default_design


def run(argv):
    """Exit code of the command line, whether it returns or argparse exits."""
    try:
        return main([str(a) for a in argv])
    except SystemExit as exc:
        return exc.code


def assert_one_line(capsys, *fragments):
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for fragment in fragments:
        assert fragment in err, err
    return err


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """A design file, a calibration CSV, its coefficients, a voltage log and a curve CSV."""
    folder = tmp_path_factory.mktemp("lab")
    design = default_design()
    design.save(folder / "design.json")
    units = built_units(design, seed=3)
    data = calibration_data(design, units, step_deg=3.0, seed=1)
    write_calibration_csv(folder / "data.csv", data["unit"], data["volts"], data["angles_deg"])
    save_calibrations(folder / "coef.json", calibrate_csv(folder / "data.csv", folds=0))
    log = voltage_log(design, units, "pitch", cycles=1, samples_per_cycle=8, seed=2)
    write_voltage_log(folder / "log.csv", log["sample"], log["unit"], log["volts"])
    from reflector_opt.model._sensors import NJL5901R_2 as m

    d = np.linspace(0.3, 3.5, 12)
    v = m.output_voltage(m.flat_coupling(d, 0.9))
    rows = "".join(f"{a},{b}\n" for a, b in zip(d, v, strict=True))
    (folder / "curve.csv").write_text("distance_mm,volts\n" + rows)
    flat = "".join(f"{a},2.0\n" for a in d)  # a constant output: no signal
    (folder / "flat.csv").write_text("distance_mm,volts\n" + flat)
    (folder / "a_folder").mkdir()
    return folder


# --- arguments ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "argv",
    [
        ["evaluate", "--no-predict"],
        ["calibrate", "data.csv", "-o", "c.json"],
        ["optimise"],
        ["report", "design.json"],
        ["tolerance", "design.json"],
        ["sweep", "design.json", "--vary", "reflector.radius_mm=8,9"],
    ],
    ids=lambda argv: argv[0],
)
def test_a_negative_seed_is_a_usage_error(tmp_path, capsys, argv):
    assert run([*argv, "--seed", "-1"]) == 2
    assert_one_line(capsys, "--seed: expected a whole number from 0 to 4294967295, got '-1'")
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize(
    "argv",
    [
        ["calibrate", "{lab}/data.csv", "--folds", "0"],
        ["estimate", "{lab}/coef.json", "{lab}/log.csv"],
        ["fit-sensor", "{lab}/curve.csv"],
    ],
    ids=lambda argv: argv[0],
)
def test_an_output_that_is_a_folder_is_refused(lab, capsys, argv):
    argv = [a.format(lab=lab) for a in argv]
    assert run([*argv, "-o", lab / "a_folder"]) == 2
    assert_one_line(capsys, "a_folder is a folder; give the name of a file to write")
    assert not list((lab / "a_folder").iterdir())


@pytest.mark.parametrize(
    ("argv", "fragment"),
    [
        (
            ["estimate", "{lab}/coef.json", "{lab}/log.csv", "--link-length-mm", "inf"],
            "> 0 and ≤ 1000 mm",
        ),
        (["estimate", "{lab}/coef.json", "{lab}/log.csv", "--link-length-mm", "1e308"], "mm"),
        (["tolerance", "{lab}/design.json", "--samples", "1000000000000"], "from 1 to 100000"),
        (
            ["sweep", "{lab}/design.json", "--vary", "reflector.radius_mm=8,9", "--samples", "-1"],
            "",
        ),
        (["fit-sensor", "{lab}/curve.csv", "--reflectance", "nan"], "--reflectance"),
        (["calibrate", "{lab}/data.csv", "--folds", "-3"], "--folds"),
        # an empty list silently stood for the default one
        (["plan-calibration", "--forms", ","], "argument --forms: expected a comma-separated"),
        (["plan-calibration", "--sizes", ""], "argument --sizes: expected a comma-separated"),
    ],
)
def test_out_of_range_numbers_are_usage_errors(lab, tmp_path, capsys, argv, fragment):
    argv = [a.format(lab=lab) for a in argv]
    assert (
        run(
            [
                *argv,
                "-o" if argv[0] in ("estimate", "fit-sensor", "calibrate") else "--out",
                tmp_path / "out",
            ]
        )
        == 2
    )
    assert_one_line(capsys, fragment)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("name", ["XYZ-1", ""])  # '' once silently meant the default
@pytest.mark.parametrize("material", [False, True])
def test_an_unknown_sensor_preset_names_the_known_ones(lab, tmp_path, capsys, name, material):
    out = tmp_path / "fitted.json"
    flags = ["--material"] if material else []
    assert run(["fit-sensor", lab / "curve.csv", *flags, "--base", name, "-o", out]) == 2
    assert_one_line(capsys, f"unknown sensor preset {name!r}; known presets: ", "NJL5901R-2")
    assert not out.exists()


# --- files ----------------------------------------------------------------------------------


def _coefficients(lab, mutate):
    data = json.loads((lab / "coef.json").read_text())
    mutate(data["units"][0])
    path = lab / "bad_coef.json"
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize(
    ("mutate", "fragment"),
    [
        (
            lambda u: u["model"].update(params=[1, 2]),
            "units[0].model.params: expected a table, got [1, 2]",
        ),
        (lambda u: u["model"].update(n_samples="many"), "units[0].model.n_samples"),
        (lambda u: u["model"].update(model=5), "units[0].model.model: expected text, got 5"),
        (lambda u: u["model"].update(solver=[1]), "units[0].model.solver"),
        (lambda u: u["model"].update(training="x"), "units[0].model.training"),
        (
            lambda u: u["model"]["training"]["rms_deg"].update(pitch_deg="x"),
            "units[0].model.training.rms_deg",
        ),
        (
            lambda u: u["model"]["params"].update(huber_threshold_deg="x"),
            "huber_threshold_deg",
        ),
        (
            lambda u: u.update(cross_validation={"folds": 2.5, "rms_deg": {}, "max_deg": {}}),
            "units[0].cross_validation.folds",
        ),
        (
            lambda u: u.update(cross_validation={"folds": 5, "rms_deg": 1, "max_deg": {}}),
            "units[0].cross_validation.rms_deg",
        ),
    ],
)
def test_malformed_coefficients_in_estimate(lab, tmp_path, capsys, mutate, fragment):
    path = _coefficients(lab, mutate)
    out = tmp_path / "angles.csv"
    assert run(["estimate", path, lab / "log.csv", "-o", out]) == 2
    assert_one_line(capsys, "reflector-opt estimate: error:", fragment)
    assert not out.exists()


DEEP = "[" * 100_000 + "]" * 100_000


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        (DEEP, "nested more than 64 levels deep"),
        ('{"a": ' * 70 + "1" + "}" * 70, "nested more than 64 levels deep"),
        ('{"format": 1, "format": 2}', "the key 'format' appears twice"),
        ('{"reflector": 1' + "0" * 400 + "}", "is too large"),
        ('{"reflector": 9' + "9" * 5000 + "}", "reflector: the number is too large"),
        ('{"reflector": 1e999}', "reflector: got inf; numbers must be finite"),
        ('{"reflector": NaN}', "reflector: got nan"),
        (b"\xff\xfe{}", "not a UTF-8 text file"),
    ],
    ids=["deep", "deep-objects", "duplicate", "huge-int", "5000-digits", "1e999", "nan", "bytes"],
)
@pytest.mark.parametrize("reader", ["evaluate", "estimate", "export"])
def test_hostile_json_is_refused_by_every_reader(lab, tmp_path, capsys, text, fragment, reader):
    path = tmp_path / "hostile.json"
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text)
    argv = {
        "evaluate": ["evaluate", "--no-predict", path],
        "estimate": ["estimate", path, lab / "log.csv", "-o", tmp_path / "a.csv"],
        "export": ["export", path, "-o", tmp_path / "cad"],
    }[reader]
    assert run(argv) == 2
    assert_one_line(capsys, str(path), fragment)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["hostile.json"]


@pytest.mark.parametrize(
    ("command", "text", "fragment"),
    [
        ("optimise", "[mechanics]\nlink_length_mm = 1" + "0" * 400, "is too large"),
        ("optimise", "[mechanics]\nlink_length_mm = inf", "got inf"),
        ("optimise", "[mechanics]\nlink_length_mm = 1e300", "≤ 1000 mm, got 1e+300"),
        ("optimise", "a = " + "[" * 2000 + "]" * 2000, "nested more than 64 levels"),
        ("optimise", "[workspace]\nstep_deg = 1e-7", "more than the limit of 1,000,000"),
        ("optimise", "[search]\npopsize = 1000000000", "search.popsize"),
        ("tolerance", "[tolerances]\ncentre_offset_mm = 1" + "0" * 400, "is too large"),
        ("tolerance", "[settings]\nn_validation = 1000000000000", "settings.n_validation"),
        ("tolerance", "[settings]\ncalibration_step_deg = 1e-7", "calibration_step_deg"),
        ("tolerance", "[run]\nworkers = 100000", "run.workers"),
        ("tolerance", "[run]\nsamples = 100000\nsobol_samples = 65536", "simulated units"),
    ],
)
def test_hostile_toml_is_refused(lab, tmp_path, capsys, command, text, fragment):
    config = tmp_path / "config.toml"
    config.write_text(text + "\n")
    out = tmp_path / "out"
    option = "--tolerances" if command == "tolerance" else "--config"
    argv = [command, option, config, "--out", out, "--quiet"]
    if command == "tolerance":
        argv.insert(1, lab / "design.json")
    assert run(argv) == 2
    assert_one_line(capsys, fragment)
    assert not out.exists()


def test_hostile_cad_parameters_are_refused(lab, tmp_path, capsys):
    params = tmp_path / "cad.toml"
    params.write_text("clearance_mm = 1" + "0" * 400 + "\n")
    assert run(["export", lab / "design.json", "--config", params, "-o", tmp_path / "cad"]) == 2
    assert_one_line(capsys, "clearance_mm: the number is too large")
    assert not (tmp_path / "cad").exists()


LONG_CELL = "1" * 200_000


@pytest.mark.parametrize(
    ("argv", "name", "text"),
    [
        (["fit-sensor", "{csv}", "-o", "{out}"], "curve", f"distance_mm,volts\n{LONG_CELL},1\n"),
        (
            ["calibrate", "{csv}", "-o", "{out}"],
            "data",
            f"unit,v1,v2,pitch_deg,roll_deg\n{LONG_CELL}\n",
        ),
        (["estimate", "{coef}", "{csv}", "-o", "{out}"], "log", f"unit,v1,v2\n1,2,{LONG_CELL}\n"),
        (
            ["fit-sensor", "{csv}", "-o", "{out}"],
            "curve",
            "distance_mm,volts\n" + "9" * 400 + ",1\n",
        ),
        (
            ["fit-sensor", "{csv}", "-o", "{out}"],
            "curve",
            "distance_mm,volts,volts\n" + "".join(f"{d},1,2\n" for d in range(1, 6)),
        ),
    ],
    ids=["curve-cell", "data-cell", "log-cell", "huge-number", "repeated-column"],
)
def test_hostile_csv_is_refused(lab, tmp_path, capsys, argv, name, text):
    csv_path, out = tmp_path / f"{name}.csv", tmp_path / "out"
    csv_path.write_text(text)
    values = {"csv": csv_path, "out": out, "coef": lab / "coef.json"}
    assert run([a.format(**values) for a in argv]) == 2
    assert_one_line(capsys, str(csv_path))
    assert not out.exists()


def test_a_long_cell_names_the_limit(tmp_path, capsys):
    path = tmp_path / "curve.csv"
    path.write_text(f"distance_mm,volts\n1,2\n{LONG_CELL},1\n")
    assert run(["fit-sensor", path, "-o", tmp_path / "out.json"]) == 2
    assert_one_line(capsys, "line 3", "a cell longer than 131,072 characters")


def test_nan_in_predicted_is_refused_and_nothing_written(lab, tmp_path, capsys):
    text = json.dumps({**default_design().to_dict(), "predicted": {"metrics": {"x": 1.0}}})
    design = tmp_path / "design.json"
    design.write_text(text.replace('"x": 1.0', '"x": NaN'))
    out = tmp_path / "out.json"
    assert run(["fit-sensor", lab / "curve.csv", "--design", design, "-o", out]) == 2
    assert_one_line(capsys, "predicted.metrics.x: got nan")
    assert not out.exists()


# --- designs that make no physical sense, and work without bound ----------------------------


def _design(tmp_path, mutate):
    data = default_design().to_dict()
    mutate(data)
    path = tmp_path / "design.json"
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize(
    ("mutate", "fragment"),
    [
        (
            lambda d: d["sensors"][0].update(position_mm=[1e308, 0, 0]),
            "sensors[0].position_mm[0]: expected a number from -1000 to 1000 mm, got 1e+308",
        ),
        (
            lambda d: d["mechanics"].update(link_length_mm=1e308),
            "mechanics.link_length_mm: expected a number > 0 and ≤ 1000 mm, got 1e+308",
        ),
        (
            lambda d: d["mechanics"].update(n_units=2.5),
            "mechanics.n_units: expected a whole number from 1 to 1000, got 2.5",
        ),
        (lambda d: d["mechanics"].update(n_units=10**9), "mechanics.n_units"),
        (
            lambda d: d["workspace"].update(step_deg=1e-7),
            "workspace.step_deg = 1e-07°: asks for 9e+16 grid poses, more than the limit",
        ),
        (
            lambda d: d["reflector"].update(radius_mm=10**300),
            "reflector.radius_mm: expected a number > 0 and ≤ 1000 mm, got 1000",
        ),
        (lambda d: d["sensors"][1].update(axis=[1e300, 1e300, 0]), "sensors[1].axis[0]"),
    ],
    ids=["position", "link", "fractional-units", "many-units", "step", "radius", "axis"],
)
def test_nonsense_designs_are_refused(tmp_path, capsys, mutate, fragment):
    assert run(["evaluate", _design(tmp_path, mutate)]) == 2
    assert_one_line(capsys, fragment)


#: The GE 6 E's figures, described as the user's own joint.
JOINT = {"bore_mm": 6, "outer_diameter_mm": 14, "inner_width_mm": 6, "outer_width_mm": 4}
JOINT |= {"ball_diameter_mm": 10, "clearance_um": 68}


def _toml_value(value):
    return f'"{value}"' if isinstance(value, str) else repr(value)


@pytest.mark.parametrize("source", ["design.json", "optimise.toml"])
@pytest.mark.parametrize(
    ("change", "fragment"),
    [
        ({"ball_diameter_mm": 15}, ".ball_diameter_mm: 15 mm must be between the bore and D"),
        ({"ball_diameter_mm": 6}, ".ball_diameter_mm: 6 mm must be between the bore and D"),
        ({"bore_mm": 14}, ".bore_mm: 14 mm must be smaller than outer_diameter_mm (14 mm)"),
        ({"bore_mm": float("nan")}, ".bore_mm: got nan"),
        ({"outer_diameter_mm": float("inf")}, ".outer_diameter_mm: got inf"),
        ({"outer_width_mm": -4}, ".outer_width_mm: "),
        ({"bore_mm": 0.006}, ".bore_mm: 0.006 mm (below 0.5 mm) looks like metres"),
        ({"clearance_um": 0.05}, ".clearance_um: 0.05 µm (below 0.5 µm) looks like millimetres"),
        ({"stop_deg": 95}, ".stop_deg: "),
        ({"stop_deg": 0}, ".stop_deg: "),
        ({"bearing": "GE6E"}, ": a joint is described and a bearing named (mechanics.bearing)"),
    ],
)
def test_a_bad_described_joint_is_one_line_and_nothing_written(
    tmp_path, capsys, source, change, fragment
):
    named = {k: v for k, v in change.items() if k == "bearing"}
    joint, out = JOINT | {k: v for k, v in change.items() if k != "bearing"}, tmp_path / "out"
    if source == "design.json":
        path = _design(tmp_path, lambda d: d["mechanics"].update(named, joint=joint))
        argv = ["export", path, "-o", out, "--no-preview"]
    else:
        lines = [f"{k} = {_toml_value(v)}" for k, v in named.items()] + ["[mechanics.joint]"]
        lines += [f"{k} = {_toml_value(v)}" for k, v in joint.items()]
        path = tmp_path / "optimise.toml"
        path.write_text("[mechanics]\n" + "\n".join(lines) + "\n")
        argv = ["optimise", "--config", path, "-o", out, "--quiet"]
    assert run(argv) == 2
    assert_one_line(capsys, f"{path.name}: mechanics.joint" + fragment)
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]


def test_smallest_refuses_a_described_joint_it_would_not_size_with(tmp_path, capsys):
    path = tmp_path / "optimise.toml"
    path.write_text("[mechanics.joint]\n" + "".join(f"{k} = {v}\n" for k, v in JOINT.items()))
    argv = ["smallest", "--config", path, "--target-deg", "0.2", "-o", tmp_path / "out"]
    assert run(argv) == 2
    assert_one_line(capsys, "mechanics.joint: smallest sizes the unit on the catalogue's")
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]


def test_a_sweep_of_a_trillion_points_is_refused_at_once(lab, tmp_path, capsys):
    out = tmp_path / "sweep"
    argv = ["sweep", lab / "design.json", "--out", out, "--quiet"]
    assert run([*argv, "--vary", "reflector.radius_mm=8:10:1000000000000"]) == 2
    assert_one_line(capsys, "--vary reflector.radius_mm: asks for 1,000,000,000,000 values")
    varies = ["--vary", "reflector.radius_mm=8:10:1000", "--vary", "noise.sigma_v=0.001:0.01:1000"]
    assert run([*argv, *varies]) == 2
    assert_one_line(capsys, "asks for 1,000,000 points, more than the limit of 10,000")
    assert not out.exists()


# --- the same feasibility rules in evaluate and export ---------------------------------------


@pytest.mark.parametrize(
    ("mutate", "fragment"),
    [
        (
            lambda d: d["reflector"].update(inner_radius_mm=5.0),
            "does not clear the bearing's outer ring",
        ),
        (
            lambda d: d["mechanics"].update(link_length_mm=11.0),
            "mechanics.link_length_mm: must exceed unit_height_mm",
        ),
        # report --no-cad ended in an internal error drawing the sensor's section
        (
            lambda d: d["sensors"][1].update(position_mm=[10.0, 0.0, 0.0]),
            "sensors: the optical axis of S2 misses the reflector",
        ),
    ],
)
def test_evaluate_refuses_what_export_refuses_with_the_same_message(
    tmp_path, capsys, mutate, fragment
):
    path = _design(tmp_path, mutate)
    messages = []
    for argv in (
        ["evaluate", path, "--no-predict"],
        ["export", path, "-o", tmp_path / "cad", "--no-preview"],
        ["report", path, "--no-cad", "-o", tmp_path / "report"],
    ):
        assert run(argv) == 2
        messages.append(assert_one_line(capsys, fragment).split(": error: ", 1)[1])
    assert messages[0] == messages[1] == messages[2]
    assert not (tmp_path / "cad").exists() and not (tmp_path / "report").exists()


@pytest.mark.parametrize(
    "argv",
    [
        ["report", "{design}", "--no-cad", "-o", "{out}"],
        ["tolerance", "{design}", "--samples", "2", "-o", "{out}"],
        ["plan-calibration", "{design}", "--sizes", "25", "--units", "1", "-o", "{out}"],
    ],
    ids=lambda argv: argv[0],
)
def test_a_sphere_that_does_not_enclose_the_rotation_centre_is_refused_by_every_command(
    tmp_path, capsys, argv
):
    """Only evaluate and export refused it (by the parts' layout); report --no-cad ended
    in an internal error drawing the sensor sections, tolerance ran on."""
    path = _design(tmp_path, lambda d: d["reflector"].update(centre_mm=[0.0, 0.0, -9.5]))
    out = tmp_path / "out"
    assert run([a.format(design=path, out=out) for a in argv]) == 2
    assert_one_line(capsys, f"{path}: reflector.centre_mm: the rotation centre must lie inside")
    assert not out.exists()


@pytest.mark.parametrize(
    ("argv", "fragment"),
    [
        (["optimise", "--config", ""], "cannot read '': an empty file name"),
        (["optimise", "--tolerances", ""], "cannot read '': an empty file name"),
        (["tolerance", "{lab}/design.json", "--tolerances", ""], "cannot read ''"),
        (["sweep", "{lab}/design.json", "--vary", "noise.sigma_v=0.002", "--tolerances", ""], "''"),
        (["export", "{lab}/design.json", "--config", ""], "cannot read ''"),
        (["evaluate", ""], "cannot read '': an empty file name"),
        (["fit-sensor", "{lab}/curve.csv", "--design", "", "-o", "f.json"], "cannot read ''"),
        (["fit-sensor", "", "-o", "f.json"], "cannot read '': an empty file name"),
        (["calibrate", "", "-o", "c.json"], "cannot read '': an empty file name"),
        (["estimate", "{lab}/coef.json", "", "-o", "a.csv"], "cannot read '': an empty file"),
        (
            ["tolerance", "{lab}/design.json", "--samples", "2", "--scheduler", ""],
            "scheduler address: expected e.g. tcp://HOST:8786, got ''",
        ),
    ],
    ids=lambda v: v if isinstance(v, str) else "-".join(a for a in v if a.startswith("-")),
)
def test_an_empty_file_name_is_refused_not_taken_for_the_default(
    lab, tmp_path, monkeypatch, capsys, argv, fragment
):
    """Each of these ran on the built-in defaults (an empty string is falsy) and wrote its
    outputs; --scheduler '' ran on local processes."""
    monkeypatch.chdir(tmp_path)
    assert run([a.format(lab=lab) for a in argv]) == 2
    assert_one_line(capsys, fragment)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "argv",
    [
        ["optimise"],
        ["report", "{lab}/design.json"],
        ["export", "{lab}/design.json"],
        ["tolerance", "{lab}/design.json"],
        ["sweep", "{lab}/design.json", "--vary", "noise.sigma_v=0.002"],
        ["plan-calibration"],
    ],
    ids=lambda argv: argv[0],
)
def test_every_folder_command_names_out_for_an_output_that_is_a_file(lab, capsys, argv):
    """export and report said 'design.json: exists and is not a folder', without --out."""
    out = lab / "data.csv"
    assert run([*(a.format(lab=lab) for a in argv), "--out", out]) == 2
    assert_one_line(capsys, f"error: --out {out}: exists and is not a folder")


# --- a warning held until the input is accepted ---------------------------------------------


def _mirror_design(tmp_path, mutate=lambda d: None):
    """A design.json written before the surface model: no specular_fraction (a warning)."""

    def change(data):
        del data["reflector"]["specular_fraction"]
        mutate(data)

    return _design(tmp_path, change)


@pytest.mark.parametrize(
    ("argv", "mutate", "fragment"),
    [
        (
            ["evaluate", "{design}", "--no-predict"],
            lambda d: d["mechanics"].update(n_units=2.5),
            "mechanics.n_units: expected a whole number from 1 to 1000, got 2.5",
        ),
        (
            ["tolerance", "{design}", "--samples", "2", "-o", "{out}"],
            lambda d: d["reflector"].update(inner_radius_mm=20.0),
            "reflector.inner_radius_mm: the inner surface lies outside the sphere",
        ),
        # the design is accepted, then the command refuses it or another input
        (
            ["evaluate", "{design}", "--no-predict"],
            lambda d: d["reflector"].update(inner_radius_mm=5.0),
            "does not clear the bearing's outer ring",
        ),
        (
            [
                "tolerance",
                "{design}",
                "--samples",
                "2",
                "--tolerances",
                "{out}.toml",
                "-o",
                "{out}",
            ],
            lambda d: None,
            "out.toml: No such file",
        ),
        (
            ["fit-sensor", "{lab}/flat.csv", "--design", "{design}", "-o", "{out}.json"],
            lambda d: None,
            "flat.csv: measured curve: the output does not change with the distance",
        ),
    ],
    ids=["refused-part", "refused-design", "refused-layout", "refused-config", "refused-curve"],
)
def test_a_design_read_as_a_mirror_and_refused_is_one_line(
    lab, tmp_path, capsys, argv, mutate, fragment
):
    """The warning 'read as 1 (a mirror)' came before the error: two lines."""
    path = _mirror_design(tmp_path, mutate)
    out = tmp_path / "out"
    assert run([a.format(design=path, out=out, lab=lab) for a in argv]) == 2
    err = assert_one_line(capsys, fragment)
    assert "warning" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["design.json"]


def test_a_design_read_as_a_mirror_and_accepted_warns_once(lab, tmp_path, capsys):
    path = _mirror_design(tmp_path)
    out = tmp_path / "fitted.json"
    assert run(["fit-sensor", lab / "curve.csv", "--design", path, "-o", out]) == 0
    err = capsys.readouterr().err
    assert err.count("warning: reflector.specular_fraction is absent: read as 1") == 1, err
    assert out.exists()


# --- a measured curve without signal ------------------------------------------------------------


@pytest.mark.parametrize(
    ("volts", "fragment"),
    [
        ("3.3", "every reading is clamped"),  # saturated at the supply: no light
        ("0.0", "every reading is clamped"),  # all zero
        ("0.2", "every reading is clamped"),  # at the saturation voltage
        ("2.0", "the output does not change with the distance"),  # constant
    ],
    ids=["supply", "zero", "saturation", "constant"],
)
@pytest.mark.parametrize("material", [False, True], ids=["sensor", "material"])
def test_a_curve_without_signal_is_refused_and_nothing_written(
    tmp_path, capsys, volts, fragment, material
):
    """fit-sensor wrote a sensor fitted to a flat line at the supply, or at zero."""
    curve = tmp_path / "curve.csv"
    rows = "".join(f"{d},{volts}\n" for d in (0.5, 1.0, 1.5, 2.0, 2.5, 3.0))
    curve.write_text("distance_mm,volts\n" + rows)
    out = tmp_path / "fitted.json"
    argv = ["fit-sensor", curve, "-o", out, *(["--material"] if material else [])]
    assert run(argv) == 2
    assert_one_line(capsys, f"error: {curve}: ", fragment)
    assert not out.exists()


# --- sweep points the design refuses ---------------------------------------------------------


@pytest.mark.parametrize(
    ("vary", "fragment"),
    [
        (
            "mechanics.n_units=2.5",
            "--vary mechanics.n_units=2.5: mechanics.n_units: "
            "expected a whole number from 1 to 1000",
        ),
        ("mechanics.n_units=1:4:7", "--vary mechanics.n_units=1.5: mechanics.n_units"),
        (
            "workspace.step_deg=1e-7",
            "--vary workspace.step_deg=1e-07: workspace.step_deg = 1e-07°: asks for 9e+16",
        ),
    ],
    ids=["fractional-units", "fractional-in-a-range", "step"],
)
def test_a_sweep_of_values_the_design_refuses_is_refused(lab, tmp_path, capsys, vary, fragment):
    """Each such point was a row 'invalid: …' of a sweep that succeeded and wrote its files."""
    out = tmp_path / "sweep"
    argv = ["sweep", lab / "design.json", "--vary", vary, "--out", out, "--quiet"]
    assert run(argv) == 2
    assert_one_line(capsys, fragment)
    assert not out.exists()


# --- output folders: only where something is written; never a mount point --------------------


def test_a_refused_log_leaves_no_output_folder(lab, tmp_path, capsys):
    """estimate made new/sub/ for angles.csv before it read the log, and left it empty."""
    log = tmp_path / "log.csv"
    log.write_text("sample,unit,v1,v2\n0,U9,1.0,2.0\n")
    out = tmp_path / "new" / "sub" / "angles.csv"
    assert run(["estimate", lab / "coef.json", log, "-o", out]) == 2
    assert_one_line(capsys, "unit(s) U9 have no calibration")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["log.csv"]


@pytest.mark.parametrize(
    "argv",
    [
        ["sweep", "{lab}/design.json", "--vary", "noise.sigma_v=0.002", "--quiet"],
        ["tolerance", "{lab}/design.json", "--samples", "2", "--quiet"],
        ["report", "{lab}/design.json", "--no-cad"],
    ],
    ids=lambda argv: argv[0],
)
def test_an_output_folder_that_is_a_mount_point_is_refused(
    lab, tmp_path, capsys, monkeypatch, argv
):
    """-o /proc, or a bind mount, was an internal error: a mount point cannot be renamed."""
    import os

    mount = tmp_path / "mnt"
    mount.mkdir()
    (mount / "kept.txt").write_text("x")
    real = os.path.ismount
    monkeypatch.setattr(os.path, "ismount", lambda p: str(p) == str(mount) or real(p))
    assert run([*(a.format(lab=lab) for a in argv), "--out", mount]) == 2
    assert_one_line(capsys, f"error: --out {mount}: is a mount point", f"{mount}/out")
    assert [p.name for p in mount.iterdir()] == ["kept.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mnt"]

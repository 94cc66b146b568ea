"""python -m principled_brdf: every subcommand, --help, and bad arguments."""

import subprocess
import sys

import numpy as np
import pytest

import principled_brdf as pb
from principled_brdf.cli import main


def run(*args):
    return subprocess.run([sys.executable, "-m", "principled_brdf", *args], capture_output=True, text=True,
                          timeout=300)


def read_png_size(path):
    with open(path, "rb") as f:
        header = f.read(24)
    assert header[:8] == b"\x89PNG\r\n\x1a\n"
    return int.from_bytes(header[16:20], "big"), int.from_bytes(header[20:24], "big")


@pytest.mark.parametrize("command", ["demo", "render", "bench", "info"])
def test_every_subcommand_has_help(command):
    result = run(command, "--help")
    assert result.returncode == 0
    assert "usage:" in result.stdout and command in result.stdout


def test_top_level_help_lists_the_commands():
    result = run("--help")
    assert result.returncode == 0
    for command in ("demo", "render", "bench", "info"):
        assert command in result.stdout


def test_info(capsys):
    assert main(["info"]) == 0
    out = capsys.readouterr().out
    assert pb.cpu_info()["isa"] in out and "threads" in out and "numpy" in out


def test_demo_writes_a_picture_and_reports_throughput(tmp_path):
    output = tmp_path / "demo.png"
    result = run("demo", "--pairs", "200000", "--repeats", "1", "--resolution", "32", "--output", str(output))
    assert result.returncode == 0, result.stderr
    for phrase in ("M pairs/s", "roofline", "sample", "float64 reference", "max relative error"):
        assert phrase in result.stdout
    width, height = read_png_size(output)
    # row titles on the left; a label strip above the presets, each metal's first row and the glass row
    assert width == 120 + 6 * 32 and height == 6 * 32 + 4 * 22 + 2 * 4


def test_render_preset_with_parameters(tmp_path, capsys):
    output = tmp_path / "gold.png"
    assert main(["render", "--preset", "gold", "--param", "roughness=0.2", "--param", "base_color=1,0.8,0.3",
                 "--resolution", "64", "--output", str(output)]) == 0
    assert read_png_size(output) == (64, 64)
    assert "roughness=0.2" in capsys.readouterr().out


def test_render_takes_the_2015_models(tmp_path, capsys):
    output = tmp_path / "glass.npy"
    assert main(["render", "--model", "disney2015", "--param", "spec_trans=1", "--param", "base_color=1,1,1",
                 "--param", "roughness=0.05", "--environment", "outdoor", "--resolution", "24", "--samples", "16",
                 "--output", str(output)]) == 0
    image = np.load(output)
    expected = pb.render.render_sphere(pb.Material(spec_trans=1, base_color=(1, 1, 1), roughness=0.05), 24,
                                       model="disney2015", environment="outdoor", samples=16)
    np.testing.assert_array_equal(image, expected)
    assert main(["render", "--model", "disney2015_thin", "--param", "diff_trans=1.5", "--resolution", "16",
                 "--samples", "8", "--output", str(tmp_path / "leaf.png")]) == 0
    with pytest.raises(SystemExit) as exit_info:
        main(["render", "--model", "disney2016", "--output", str(tmp_path / "x.png")])
    assert exit_info.value.code == 2 and "--model" in capsys.readouterr().err


def test_render_writes_linear_npy_and_exr_and_switches_the_sky(tmp_path):
    common = ["render", "--preset", "chrome", "--resolution", "32", "--samples", "8"]
    assert main(common + ["--environment", "sky", "--output", str(tmp_path / "sky.npy")]) == 0
    assert main(common + ["--no-environment", "--output", str(tmp_path / "key.npy")]) == 0
    assert main(common + ["--environment", "sky", "--exposure", "2", "--output", str(tmp_path / "sky2.npy")]) == 0
    sky, key, brighter = (np.load(tmp_path / f"{name}.npy") for name in ("sky", "key", "sky2"))
    assert sky.shape == (32, 32, 3) and sky.dtype == np.float32
    # chrome reflects the sky: without it most of the sphere is black; exposure scales the linear values
    assert np.count_nonzero(key.sum(-1) > 0.01) < np.count_nonzero(sky.sum(-1) > 0.01) // 4
    np.testing.assert_allclose(brighter, 2 * sky, rtol=1e-6)
    expected = pb.render.render_sphere(pb.presets.get("chrome"), 32, samples=8)
    np.testing.assert_allclose(sky, expected, rtol=1e-6)
    import OpenEXR  # a test extra
    assert main(common + ["--environment", "sky", "--output", str(tmp_path / "sky.exr")]) == 0
    with OpenEXR.File(str(tmp_path / "sky.exr")) as exr:
        np.testing.assert_array_equal(exr.channels()["RGB"].pixels, sky)


def test_render_lights_by_the_studio_by_default_and_takes_maps_tone_and_compensation(tmp_path):
    common = ["render", "--preset", "gold", "--resolution", "24", "--samples", "4"]
    gold = pb.presets.get("gold")
    assert main(common + ["--output", str(tmp_path / "studio.npy")]) == 0
    np.testing.assert_allclose(np.load(tmp_path / "studio.npy"),
                               pb.render.render_sphere(gold, 24, environment="studio", samples=4), rtol=1e-6)
    assert main(common + ["--environment", "outdoor", "--light-intensity", "2", "--energy-compensation",
                          "--output", str(tmp_path / "outdoor.npy")]) == 0
    np.testing.assert_allclose(np.load(tmp_path / "outdoor.npy"),
                               pb.render.render_sphere(gold, 24, environment="outdoor", samples=4, light_intensity=2.0,
                                                       energy_compensation=True), rtol=1e-6)
    # a map file, written here: a bright band overhead
    import OpenEXR

    band = np.full((8, 16, 3), 0.02, np.float32)
    band[1:3] = 5.0
    with OpenEXR.File({"type": OpenEXR.scanlineimage}, {"RGB": band}) as exr:
        exr.write(str(tmp_path / "band.exr"))
    assert main(common + ["--environment", str(tmp_path / "band.exr"), "--output", str(tmp_path / "band.npy")]) == 0
    np.testing.assert_allclose(np.load(tmp_path / "band.npy"),
                               pb.render.render_sphere(gold, 24, environment=band, samples=4), rtol=1e-6)
    linear = np.load(tmp_path / "studio.npy")
    for tone in ("filmic", "reinhard", "clip"):
        assert main(common + ["--tone", tone, "--output", str(tmp_path / f"{tone}.png")]) == 0
        import matplotlib.image

        read = np.round(matplotlib.image.imread(str(tmp_path / f"{tone}.png"))[..., :3] * 255)
        np.testing.assert_array_equal(read, pb.render.to_srgb8(linear, curve=tone))


def test_bench_compares_with_numpy(capsys):
    assert main(["bench", "--pairs", "20000", "--repeats", "1"]) == 0
    out = capsys.readouterr().out
    assert "numpy float32" in out and "x numpy" in out


@pytest.mark.parametrize(
    "args, message",
    [
        (["render", "--output", "x.png", "--param", "roughnes=0.3"], "expected NAME=VALUE"),
        (["render", "--output", "x.png", "--param", "base_color=1,2"], "base_color: expected 3"),
        (["render", "--output", "x.png", "--param", "roughness=-1"], "roughness: -1.0 is outside its domain"),
        (["render", "--output", "x.png", "--param", "base_color=0.5,nan,0.5"], "base_color: nan is outside its domain"),
        (["render", "--output", "x.png", "--param", "anisotropic=1.5"], "anisotropic: 1.5 is outside its domain [0, 1]"),
        (["render", "--output", "x.tiff"], "cannot write '.tiff' images; supported: .png, .exr, .npy"),
        (["render", "--output", "picture"], "cannot write 'a file without an extension' images"),
        (["demo", "--output", "x.exr"], "cannot write '.exr' images; supported: .png"),
        (["render", "--output", "x.png", "--preset", "unobtainium"], "invalid choice"),
        (["render", "--output", "x.png", "--light", "0,0"], "three finite comma-separated numbers"),
        (["render", "--output", "x.png", "--environment", "garden"],
         "expected sky, studio, outdoor, none or a .exr/.hdr latitude-longitude map, got 'garden'"),
        (["render", "--output", "x.png", "--environment", "nowhere.hdr"], "no such file: 'nowhere.hdr'"),
        (["render", "--output", "x.png", "--tone", "aces"], "invalid choice: 'aces'"),
        (["render", "--output", "x.png", "--resolution", "0"], "expected a positive integer"),
        (["render"], "--output"),
        (["demo", "--pairs", "many"], "expected a positive integer"),
        (["frobnicate"], "invalid choice"),
        ([], "required"),
    ],
)
def test_bad_arguments_give_a_clear_message_and_nonzero_exit(args, message):
    result = run(*args)
    assert result.returncode != 0
    assert message in result.stderr, result.stderr


def test_render_to_an_unwritable_path_fails_cleanly(tmp_path):
    result = run("render", "--resolution", "8", "--output", str(tmp_path / "missing" / "x.png"))
    assert result.returncode == 2
    assert "error:" in result.stderr and "Traceback" not in result.stderr


def test_presets_are_inside_the_domains():
    for name in pb.presets.names():
        material = pb.presets.get(name)  # Material checks every domain
        assert material.is_uniform
    assert {"gold", "chrome", "blue_rubber", "car_paint", "satin_cloth", "brushed_metal"} <= set(pb.presets.names())
    assert pb.presets.get("car_paint").clearcoat > 0 and pb.presets.get("satin_cloth").sheen > 0
    assert pb.presets.get("brushed_metal").anisotropic > 0
    with pytest.raises(ValueError, match="unknown preset 'nope'"):
        pb.presets.get("nope")


def test_write_png_round_trips_through_matplotlib(tmp_path):
    image = np.zeros((4, 5, 3), np.uint8)
    image[1, 2] = (255, 128, 0)
    pb.render.write_png(str(tmp_path / "x.png"), image)
    import matplotlib.image

    read = matplotlib.image.imread(str(tmp_path / "x.png"))
    np.testing.assert_allclose(read[..., :3] * 255, image, atol=0.6)


@pytest.mark.parametrize(
    "args, option",
    [
        (["render", "--resolution", "999999999", "--output", "x.png"], "--resolution"),
        (["bench", "--pairs", "99999999999"], "--pairs"),
        (["demo", "--pairs", "99999999999"], "--pairs"),
        (["render", "--exposure", "nan", "--output", "x.png"], "--exposure"),
        (["render", "--exposure", "inf", "--output", "x.png"], "--exposure"),
        (["render", "--exposure", "-1", "--output", "x.png"], "--exposure"),
        (["render", "--light", "nan,0,1", "--output", "x.png"], "--light"),
        (["render", "--light", "inf,0,1", "--output", "x.png"], "--light"),
        (["render", "--light", "0,0,0", "--output", "x.png"], "--light"),
        (["render", "--light-intensity", "-1", "--output", "x.png"], "--light-intensity"),
        (["render", "--light-intensity", "nan", "--output", "x.png"], "--light-intensity"),
        (["render", "--environment", "garden", "--output", "x.png"], "--environment"),
        (["render", "--environment", "map.png", "--output", "x.png"], "--environment"),
        (["render", "--environment", "missing.exr", "--output", "x.png"], "--environment"),
        (["render", "--tone", "aces", "--output", "x.png"], "--tone"),
        (["render", "--energy-compensation=yes", "--output", "x.png"], "--energy-compensation"),
        (["render", "--resolution", "16384", "--samples", "1024", "--output", "x.png"], "--samples"),
    ],
)
def test_options_beyond_what_fits_or_makes_sense_are_one_line_errors(args, option, tmp_path):
    result = subprocess.run([sys.executable, "-m", "principled_brdf", *args], capture_output=True, text=True,
                            timeout=120, cwd=tmp_path)
    assert result.returncode == 2
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert "Traceback" not in result.stderr and option in lines[-1] and "error" in lines[-1]
    assert not (tmp_path / "x.png").exists()

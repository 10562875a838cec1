"""describe() and distance(): parity with `lidarloop describe` / `lidarloop distance`, array
layouts and dtypes, and the documented errors for bad input."""

import json
import subprocess

import numpy as np
import pytest

import lidarloop

METHODS = ["height", "range", "ndt", "scancontext"]


@pytest.fixture(scope="module")
def scan_file(data_dir):
    return data_dir / "samples" / "courtyard.bin"


@pytest.fixture(scope="module")
def points(scan_file):
    return lidarloop.read_scan(scan_file)


def run_cli(cli, *args):
    return subprocess.run([str(cli), *map(str, args)], check=True, capture_output=True, text=True).stdout


@pytest.mark.parametrize("method", METHODS)
def test_describe_gives_the_cli_json(cli, scan_file, points, method):
    expected = json.loads(run_cli(cli, "describe", scan_file, "--method", method))
    from_array = lidarloop.describe(points, method)
    from_file = lidarloop.describe(scan_file, method)
    assert from_array.to_dict() == expected
    assert from_file.to_dict() == expected
    assert from_array.method == method
    assert from_array.points_used == expected["points_used"]
    if method == "ndt":
        assert len(from_array.descriptors) == len(expected["descriptors"])
        for ours, theirs in zip(from_array.descriptors, expected["descriptors"]):
            np.testing.assert_array_equal(ours["F"], np.array(theirs["F"], dtype=np.float32))
            np.testing.assert_array_equal(ours["R_aligned_sensor"], theirs["R_aligned_sensor"])
    elif method == "scancontext":
        np.testing.assert_array_equal(from_array.bins, np.array(expected["bins"], dtype=np.float32))
        assert from_array.bins.shape == (20, 60)
        assert from_array.ring_key == pytest.approx(expected["ring_key"])
    else:
        np.testing.assert_array_equal(from_array.bins, expected["bins"])
        assert from_array.min == expected["min"] and from_array.max == expected["max"]


def test_describe_histogram_keywords_are_the_cli_flags(cli, scan_file, points):
    expected = json.loads(
        run_cli(cli, "describe", scan_file, "--method", "range", "--bins", 40, "--max", 50, "--out-of-range", "drop")
    )
    ours = lidarloop.describe(points, "range", bins=40, max=50.0, out_of_range="drop")
    assert ours.to_dict() == expected
    assert ours.bins.shape == (40,)


@pytest.mark.parametrize("method", METHODS)
def test_distance_is_the_cli_distance(cli, data_dir, method):
    a, b = data_dir / "samples" / "corner_a.pcd", data_dir / "samples" / "corner_b.ply"
    expected = float(run_cli(cli, "distance", a, b, "--method", method))
    ours = lidarloop.distance(lidarloop.describe(a, method), lidarloop.describe(b, method))
    assert ours == pytest.approx(expected, rel=1e-8, abs=1e-12)


def test_histogram_bins_are_a_normalised_histogram_of_the_ranges(points):
    """Independent of the C++: np.histogram of the clamped ranges."""
    ours = lidarloop.describe(points, "range", bins=50, min=0.0, max=40.0)
    ranges = np.clip(np.linalg.norm(points.astype(np.float64), axis=1), 0.0, 40.0)
    expected, _ = np.histogram(ranges, bins=50, range=(0.0, 40.0))
    np.testing.assert_allclose(ours.bins, expected / len(points), atol=2.0 / len(points))
    assert ours.bins.sum() == pytest.approx(1.0)


def test_bins_view_is_read_only_and_outlives_nothing(points):
    bins = lidarloop.describe(points, "range").bins
    with pytest.raises(ValueError):
        bins[0] = 1.0
    assert bins.sum() == pytest.approx(1.0)  # the descriptor is kept alive by the view


@pytest.mark.parametrize("method", METHODS)
def test_float32_float64_and_non_contiguous_arrays_give_the_same_descriptor(points, method):
    reference = lidarloop.describe(points, method).to_dict()
    as_float64 = points.astype(np.float64)
    fortran = np.asfortranarray(points)
    with_intensity = np.hstack([points, np.ones((len(points), 1), np.float32)])
    strided = np.repeat(points, 2, axis=0)[::2]  # every other row: a non-contiguous view
    wide_columns = np.zeros((len(points), 6))[:, ::2]
    wide_columns[:] = points
    for variant in (as_float64, fortran, with_intensity, with_intensity[:, :3], strided, wide_columns):
        assert not (variant is points)
        assert lidarloop.describe(variant, method).to_dict() == reference


def test_distance_is_zero_to_itself_and_symmetric(points):
    a = lidarloop.describe(points, "height")
    b = lidarloop.describe(points[::3], "height")
    assert lidarloop.distance(a, a) == 0.0
    assert lidarloop.distance(a, b) == lidarloop.distance(b, a) == a.distance(b) > 0.0


def test_scancontext_match_gives_the_yaw_of_a_turned_scan(points):
    config = {"scancontext": {"max_range_m": 40.0}}
    a = lidarloop.describe(points, "scancontext", config=config)
    yaw = np.deg2rad(12.0)  # two sectors
    turn = np.array([[np.cos(yaw), -np.sin(yaw), 0], [np.sin(yaw), np.cos(yaw), 0], [0, 0, 1]])
    b = lidarloop.describe((points @ turn.T).astype(np.float32), "scancontext", config=config)
    match = lidarloop.scancontext_match(a, b)
    assert match["shift"] == 2
    assert match["yaw_rad"] == pytest.approx(yaw)
    assert match["distance"] == lidarloop.distance(a, b) < 0.05
    with pytest.raises(lidarloop.ConfigError):
        lidarloop.scancontext_match(lidarloop.describe(points, "range"), a)


def test_a_methods_parameters_are_keywords_of_describe(cli, scan_file, points):
    """Derived from the method's declaration (docs/options.md): the same keys as its YAML
    section and its flags, read and checked like a config dict."""
    keys = [p["key"] for p in lidarloop.method_parameters("scancontext")]
    assert keys == ["rings", "sectors", "max_range_m", "sensor_height_m", "ring_key_candidates"]
    rings = lidarloop.method_parameters("scancontext")[0]
    assert rings == {"key": "rings", "type": "int", "default": 20, "min": 1.0, "max": 200.0,
                     "open": False, "unit": "", "help": "N_r, rings of equal width up to max_range_m"}
    d = lidarloop.describe(points, "scancontext", rings=10, max_range_m=40.0)
    assert d.bins.shape == (10, 60)
    assert d.to_dict() == lidarloop.describe(
        points, "scancontext", config={"scancontext": {"rings": 10, "max_range_m": 40.0}}).to_dict()
    flags = json.loads(run_cli(cli, "describe", scan_file, "--method", "scancontext",
                               "--scancontext-rings", "10", "--scancontext-max-range-m", "40"))
    assert d.to_dict() == flags
    with pytest.raises(lidarloop.ReadError, match="key 'scancontext.ringz': unknown key"):
        lidarloop.describe(points, "scancontext", ringz=10)
    with pytest.raises(lidarloop.ReadError, match=r"scancontext.rings must be in \[1, 200\]"):
        lidarloop.describe(points, "scancontext", rings=0)
    with pytest.raises(lidarloop.ReadError, match="key 'histogram.rings': unknown key"):
        lidarloop.describe(points, "range", rings=10)


def test_histogram_and_ndt_parameters_are_keywords_of_describe(cli, scan_file, points):
    """Their sections are declared like scancontext's: method_parameters lists them (height and
    range share the histogram section) and describe takes them as keywords."""
    histogram = [p["key"] for p in lidarloop.method_parameters("height")]
    assert histogram == ["bins", "up_vector", "sensor_height_m", "height_min_m", "height_max_m",
                         "range_min_m", "range_max_m", "out_of_range"]
    assert lidarloop.method_parameters("range") == lidarloop.method_parameters("height")
    up = lidarloop.method_parameters("height")[1]
    assert (up["type"], up["default"], up["min"]) == ("str", "fixed", None)
    ndt = {p["key"]: p for p in lidarloop.method_parameters("ndt")}
    assert list(ndt)[:3] == ["cell_size_m", "min_points_per_cell", "eigen_ratio_threshold"]
    assert ndt["cell_size_m"] == {"key": "cell_size_m", "type": "float", "default": 0.5,
                                  "min": 0.01, "max": 100.0, "open": False, "unit": "m",
                                  "help": "q, side of an NDT cell; cells overlap by q/2"}
    assert ndt["eigen_ratio_threshold"]["open"] is True
    assert ndt["range_limits_m"]["default"] == [3.0, 6.0, 9.0, 15.0]
    d = lidarloop.describe(points, "ndt", cell_size_m=1.0, planar_classes=4)
    assert d.to_dict() == lidarloop.describe(
        points, "ndt", config={"ndt": {"cell_size_m": 1.0, "planar_classes": 4}}).to_dict()
    flags = json.loads(run_cli(cli, "describe", scan_file, "--method", "ndt",
                               "--ndt-cell-size-m", "1", "--ndt-planar-classes", "4"))
    assert lidarloop.describe(scan_file, "ndt", cell_size_m=1.0, planar_classes=4).to_dict() == flags
    with pytest.raises(lidarloop.ReadError, match=r"ndt.cell_size_m must be in \[0.01, 100\]"):
        lidarloop.describe(points, "ndt", cell_size_m=0.0)
    h = lidarloop.describe(points, "height", height_min_m=8.0, height_max_m=10.0)
    assert (h.min, h.max) == (8.0, 10.0)
    with pytest.raises(lidarloop.ReadError, match="unknown up vector mode"):
        lidarloop.describe(points, "height", up_vector="sideways")


@pytest.mark.parametrize(
    "bad, error",
    [
        (np.zeros((10, 2), np.float32), lidarloop.ShapeError),
        (np.zeros((10, 5), np.float32), lidarloop.ShapeError),
        (np.zeros(30, np.float32), lidarloop.ShapeError),
        (np.zeros((10, 3, 1), np.float32), lidarloop.ShapeError),
        (np.zeros((10, 3), np.int32), lidarloop.DtypeError),
        (np.zeros((10, 3), np.float16), lidarloop.DtypeError),
        (np.zeros((10, 3), ">f4"), lidarloop.DtypeError),
        ([[0.0, 0.0, 1.0]], lidarloop.DtypeError),
    ],
)
def test_bad_arrays_raise_the_documented_errors(bad, error):
    with pytest.raises(error, match="points"):
        lidarloop.describe(bad, "range")


def test_wrong_dtype_is_a_type_error_and_wrong_shape_a_value_error():
    with pytest.raises(TypeError):
        lidarloop.describe(np.zeros((10, 3), np.int64))
    with pytest.raises(ValueError):
        lidarloop.describe(np.zeros((10, 2)))


@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_non_finite_points_raise_unless_skipped(points, value):
    bad = points.copy()
    bad[7, 1] = value
    with pytest.raises(lidarloop.NonFiniteError, match="row 7"):
        lidarloop.describe(bad, "range")
    skipped = lidarloop.describe(bad, "range", skip_non_finite=True)
    assert skipped.points_skipped == 1
    assert skipped.points_used == len(points) - 1


def test_an_empty_scan_raises_empty_input_error():
    with pytest.raises(lidarloop.EmptyInputError):
        lidarloop.describe(np.zeros((0, 3), np.float32), "height")


def test_config_errors_name_the_field(points):
    with pytest.raises(lidarloop.ConfigError, match="bins"):
        lidarloop.describe(points, "range", bins=0)
    with pytest.raises(lidarloop.ConfigError, match="ndt"):
        lidarloop.describe(points, "ndt", bins=10)
    # As `lidarloop describe --up pca` without --method height: the default is range.
    with pytest.raises(lidarloop.ConfigError, match="height method only"):
        lidarloop.describe(points, up="pca")
    with pytest.raises(lidarloop.ConfigError, match="height method only"):
        lidarloop.describe(points, "range", sensor_height=1.7)
    assert lidarloop.describe(points, "height", up="pca").method == "height"
    with pytest.raises(lidarloop.ConfigError, match="height"):
        lidarloop.describe(points, "no-such-method")
    with pytest.raises(lidarloop.ReadError, match="no_such_key"):
        lidarloop.describe(points, config={"histogram": {"no_such_key": 1}})


def test_config_dict_and_file_override_the_defaults(points, tmp_path):
    by_dict = lidarloop.describe(points, config={"method": "range", "histogram": {"bins": 30}})
    config_file = tmp_path / "config.yaml"
    config_file.write_text("method: range\nhistogram:\n  bins: 30\n")
    by_file = lidarloop.describe(points, config=config_file)
    assert by_dict.method == "range" and len(by_dict.bins) == 30
    assert by_file.to_dict() == by_dict.to_dict()


def test_describe_of_a_missing_file_raises_read_error(tmp_path):
    with pytest.raises(lidarloop.ReadError) as error:
        lidarloop.describe(tmp_path / "missing.pcd")
    assert error.value.file == str(tmp_path / "missing.pcd")


def test_fields_of_another_method_are_attribute_errors(points):
    histogram = lidarloop.describe(points, "range")
    assert not hasattr(histogram, "descriptors") and not hasattr(histogram, "up")
    ndt = lidarloop.describe(points, "ndt")
    assert not hasattr(ndt, "bins")


def test_method_names_thresholds_and_config_dump(cli):
    assert lidarloop.method_names()[: len(METHODS)] == METHODS
    assert lidarloop.is_match("range", 0.001, lidarloop.default_threshold("range"))
    assert lidarloop.dump_config() == run_cli(cli, "dump-config")


def test_a_config_path_with_a_nul_is_refused_not_cut(tmp_path):
    (tmp_path / "a").write_text("histogram:\n  bins: 7\n")  # what the cut path would read
    with pytest.raises(lidarloop.ReadError, match="NUL"):
        lidarloop.dump_config(str(tmp_path / "a") + "\0b.yaml")


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_a_scan_of_only_non_finite_points_raises_non_finite_error(dtype):
    points = np.full((5, 3), np.nan, dtype)
    with pytest.raises(lidarloop.NonFiniteError, match="row 0"):
        lidarloop.describe(points, "range")
    with pytest.raises(lidarloop.EmptyInputError):
        lidarloop.describe(points, "range", skip_non_finite=True)

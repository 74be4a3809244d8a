"""The Python package against the command line and against what the data must satisfy."""

import subprocess
import threading
import time

import numpy as np
import pytest

import railforce


def test_simulate_in_a_train_matches_the_cli_and_refuses_a_position_in_no_train(cli, tmp_path):
    out = tmp_path / "train.npz"
    subprocess.run(
        [str(cli), "simulate", "--track", "curve_r800", "--duration", "1", "--settle", "0.5",
         "--seed", "3", "--consist", "daqin_10kt", "--position", "0.5", "--out", str(out)],
        check=True, capture_output=True,
    )
    ref = np.load(out)
    py = railforce.simulate(track="curve_r800", duration_s=1, settle_s=0.5, seed=3,
                            consist="daqin_10kt", position=0.5)
    assert list(py) == list(ref.files)
    for name in ("coupler_front_force", "coupler_rear_force", "coupler_front_yaw", "coupler_rear_yaw"):
        np.testing.assert_array_equal(py[name], ref[name], err_msg=name)
    assert py["coupler_front_force"].mean() > 0  # mid-train at constant speed: in tension
    with pytest.raises(ValueError, match="no train"):
        railforce.simulate(track="curve_r800", duration_s=1, position=0.5)


def test_simulate_returns_the_cli_numbers_for_the_same_seed(cli, tmp_path):
    out = tmp_path / "run.npz"
    subprocess.run(
        [str(cli), "simulate", "--track", "curve_r400", "--speed-kmh", "60", "--duration", "1",
         "--settle", "0.5", "--seed", "7", "--out", str(out)],
        check=True, capture_output=True,
    )
    ref = np.load(out)
    py = railforce.simulate(track="curve_r400", speed_kmh=60, duration_s=1, settle_s=0.5, seed=7)
    assert list(py) == list(ref.files)
    for name in ref.files:
        np.testing.assert_array_equal(py[name], ref[name], err_msg=name)
    # A subset keeps time_s first; as_frame gives a DataFrame with the same numbers.
    sub = railforce.simulate(track="curve_r400", speed_kmh=60, duration_s=1, settle_s=0.5,
                             seed=7, channels=["w1l_force_z"], as_frame=True)
    assert list(sub.columns) == ["time_s", "w1l_force_z"]
    np.testing.assert_array_equal(sub["w1l_force_z"].to_numpy(), ref["w1l_force_z"])


def test_a_bad_track_name_raises_value_error_listing_the_builtins():
    with pytest.raises(ValueError) as e:
        railforce.simulate(track="curve_r123", duration_s=1)
    msg = str(e.value)
    assert "curve_r123" in msg and "curve_r400" in msg and "tangent" in msg
    assert "curve_r400" in railforce.builtins()
    with pytest.raises(ValueError, match="channel nope"):
        railforce.simulate(track="tangent", duration_s=0.1, settle_s=0.1, channels=["nope"])
    with pytest.raises(ValueError, match="speed"):
        railforce.simulate(track="tangent", speed_kmh=-5)
    with pytest.raises(FileNotFoundError):
        railforce.open_dataset("/nonexistent/data")


def test_windows_never_cross_a_run_boundary_and_respect_the_split(demo_data):
    ds = railforce.open_dataset(demo_data)
    assert len(ds) == 12 and ds.labels == ["w1l_force_y", "w1l_force_z"]
    assert ds.manifest["plan_name"] == "demo"
    split = ds.split
    assert split["kind"] == "seeds"
    seeds = {p: set(split[p]) for p in ("train", "val", "test")}
    assert not (seeds["train"] & seeds["test"]) and not (seeds["val"] & seeds["test"])
    runs = ds.runs
    chan = ds.channels
    for part in ("train", "val", "test"):
        w = railforce.windows(ds, part, window=20, label="centre")
        n = len(w["run"])
        assert w["x"].shape == (n, 20, 21) and w["y"].shape == (n, 2)
        assert w["x"].dtype == np.float32 and w["x"].flags["C_CONTIGUOUS"]
        for r, s in zip(w["run"], w["start"]):
            assert s + 20 <= runs[r][2], "a window crosses the end of its run"
            assert runs[r][1] in seeds[part], "a window of another part's seed"
        # Every window is its run's rows, standardised with the training statistics.
        k = n // 2
        r, s = int(w["run"][k]), int(w["start"][k])
        cols = ds.run(r)
        # Matched protocol: every part reads the data set's noisy copies (training draws
        # fresh noise per epoch on top of the clean inputs instead: WindowDataset).
        raw = np.stack([cols[c + "_noisy"][s:s + 20] for c in w["channels"]], axis=1)
        np.testing.assert_allclose(
            w["x"][k], (raw - w["input_mean"]) / w["input_std"], rtol=1e-4, atol=1e-4)
        label = np.array([cols[t][s + w["label_offset"]] for t in w["targets"]])
        np.testing.assert_allclose(
            w["y"][k] * w["target_std"] + w["target_mean"], label, rtol=1e-5, atol=1e-2)
        assert all(c in chan for c in w["channels"])


def test_identify_of_a_dataframe_equals_the_cli_on_the_same_file(cli, demo_data, demo_model,
                                                                 tmp_path):
    import pandas as pd

    run = sorted(demo_data.glob("curve_r400_v60_seed4.npz"))[0]
    out = tmp_path / "identified.csv"
    subprocess.run([str(cli), "identify", "--model", str(demo_model), "--input", str(run),
                    "--out", str(out)], check=True, capture_output=True)
    ref = pd.read_csv(out)
    frame = pd.DataFrame(dict(np.load(run)))
    got, report = railforce.identify(demo_model, frame)
    assert isinstance(got, pd.DataFrame)
    assert list(got.columns) == list(ref.columns)
    for c in ref.columns:
        # The CLI prints forces to 0.1 N, indices to 1e-4, times to 1 ms.
        tol = 0.051 if c.endswith("_N") else 6e-4 if c in ("time_s", "s_m") else 5.1e-5
        np.testing.assert_allclose(got[c].to_numpy(), ref[c].to_numpy(), atol=tol, rtol=0,
                                   err_msg=c)
    lo, hi = got["w1l_force_z_lo_N"], got["w1l_force_z_hi_N"]
    assert (lo <= got["w1l_force_z_N"]).all() and (got["w1l_force_z_N"] <= hi).all()
    assert report["calibrated"] and report["limits"]["y_over_q"] > 0
    # A column missing is named.
    with pytest.raises(ValueError, match="frame_l_acc_y"):
        railforce.identify(demo_model, frame.drop(columns=[c for c in frame.columns
                                                            if c.startswith("frame_l_acc_y")]))


def test_assess_and_contact(demo_data):
    run = demo_data / "curve_r400_v60_seed1.npz"
    a = railforce.assess(run, track="curve_r400")
    assert a["rows"] and all(r["limit"] > 0 for r in a["rows"])
    assert {"section", "quantity", "value", "limit", "pass"} <= set(a["rows"][0])
    same = railforce.assess(dict(np.load(run)), track="curve_r400")
    assert [r["value"] for r in same["rows"]] == [r["value"] for r in a["rows"]]
    c = railforce.contact(y_mm=0.0)
    q = [w["Q_N"] for w in c["wheels"]]
    # Centred and at rest on the loaded C80: each wheel carries the static load, 122.6 kN.
    np.testing.assert_allclose(q, [122.6e3, 122.6e3], rtol=2e-3)
    shifted = railforce.contact(y_mm=5.0)
    left, right = shifted["wheels"]
    assert left["side"] == "left" and left["patches"][0]["rolling_radius_m"] > \
        right["patches"][0]["rolling_radius_m"]


def test_threads_running_two_simulations_at_once_finish_faster_than_one_after_the_other():
    def one():
        railforce.simulate(track="tangent", duration_s=8.0, settle_s=0.5, seed=1)

    def two_in_threads():
        threads = [threading.Thread(target=one) for _ in range(2)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()

    def timed(f):
        t0 = time.perf_counter()
        f()
        return time.perf_counter() - t0

    one()  # warm the contact table and the built-in files
    # With the interpreter held, two threads take at least the serial time in every round. With
    # it released, two cores finish near half of it; a shared CI machine steals cores now and
    # then (one round measured 0.81 of the serial time), so the best of five rounds decides.
    ratios = []
    for _ in range(5):
        serial = timed(lambda: (one(), one()))
        parallel = timed(two_in_threads)
        ratios.append(parallel / serial)
        if ratios[-1] < 0.8:
            break
    assert min(ratios) < 0.8, ratios


def test_simulate_on_sleepers_matches_the_cli(cli, tmp_path):
    out = tmp_path / "sleepers.npz"
    subprocess.run(
        [str(cli), "simulate", "--track", "curve_r400", "--speed-kmh", "60", "--duration", "0.5",
         "--settle", "0.5", "--seed", "7", "--rail-support", "discrete", "--out", str(out)],
        check=True, capture_output=True,
    )
    ref = np.load(out)
    py = railforce.simulate(track="curve_r400", speed_kmh=60, duration_s=0.5, settle_s=0.5, seed=7,
                            rail_support="discrete")
    for name in ("w1l_force_z", "w1l_force_y", "carbody_acc_z"):
        np.testing.assert_array_equal(py[name], ref[name], err_msg=name)
    with pytest.raises(ValueError, match="discrete sleepers"):
        railforce.simulate(track="curve_r400", duration_s=0.5, rail_support="discrete",
                           integrator="heun")


def test_simulate_over_roughness_matches_the_cli(cli, tmp_path):
    out = tmp_path / "rough.npz"
    subprocess.run(
        [str(cli), "simulate", "--track", "tangent", "--speed-kmh", "80", "--duration", "0.3",
         "--settle", "0.3", "--seed", "7", "--roughness", "cnossos_m", "--out", str(out)],
        check=True, capture_output=True,
    )
    ref = np.load(out)
    py = railforce.simulate(track="tangent", speed_kmh=80, duration_s=0.3, settle_s=0.3, seed=7,
                            roughness="cnossos_m")
    np.testing.assert_array_equal(py["w1l_force_z"], ref["w1l_force_z"])
    with pytest.raises(ValueError, match="too coarse"):
        railforce.simulate(track="tangent", duration_s=0.3, roughness="iso3095", dt=5e-4)

"""The physical design: information-matrix prediction against a Monte Carlo of the estimator,
the multisine records, the end-to-end run and the command line's refusals."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest
from typer.testing import CliRunner

from stewartid.cli.application import app
from stewartid.datasets.dataset import Dataset
from stewartid.design.candidates import Design
from stewartid.design.multisine import MultisineRecord, all_dofs_multisine, multisine_design
from stewartid.design.physical.information import (
    design_rows,
    parameter_sizes,
    played_states,
    predict_parameters,
)
from stewartid.design.physical.payload_accuracy import (
    distance_quantile,
    held_share,
    payload_jacobian,
)
from stewartid.design.physical.search import (
    candidate,
    commanded_limit_use,
    plant_scales,
    refine_for_plant,
    scale_to_limits,
    search_design,
)
from stewartid.design.physical.workflow import run_physical_design
from stewartid.model import regressor as reg
from stewartid.model.kinematics import inverse_kinematics, leg_jacobian
from stewartid.physical.estimator import PhysicalIdentifier
from stewartid.platform import load_platform
from stewartid.simulation import SensorNoise

PAYLOAD = {"mass": 2000.0, "com": [-0.20, 0.30, -0.50],
           "inertia": [1800.0, 2200.0, 2600.0, -120.0, 80.0, 160.0]}


@pytest.fixture(scope="module")
def loaded():
    return load_platform("paper").replace(
        friction__coulomb=30.0, **{f"payload__{k}": v for k, v in PAYLOAD.items()})


def test_multisine_record_derivatives_match_finite_differences():
    record = MultisineRecord([[0.02, 0.01]] * 3 + [[0.01, 0.005]] * 3,
                             [[0.3, 0.75], [0.45, 0.9], [0.6, 1.05]] * 2,
                             np.arange(12.0).reshape(6, 2), 10.0)
    h = 1e-4
    t = np.linspace(0.5, 9.5, 7)
    q, q_dot, q_ddot = record.evaluate_offsets(t)
    plus, minus = record.evaluate_offsets(t + h)[0], record.evaluate_offsets(t - h)[0]
    # central differences: error h^2 / 6 q''' (q''' <= A (2 pi f)^3 plus the fade's terms)
    assert np.allclose((plus - minus) / (2 * h), q_dot, atol=1e-7)
    assert np.allclose((plus - 2 * q + minus) / h ** 2, q_ddot, atol=1e-4)
    at_ends = record.evaluate_offsets(np.array([0.0, 10.0]))
    assert all(np.allclose(x, 0.0, atol=1e-15) for x in at_ends)


@pytest.mark.slow
def test_information_matrix_predicts_the_estimators_spread(loaded):
    """Rigid-body data of a short record (the commanded motion, the model's forces), white
    force noise only; the spread of the payload fit over seeds against the prediction."""
    design = all_dofs_multisine(20.0)
    rate = loaded.sensors.sample_rate
    t = np.arange(int(20.0 * rate) + 1) / rate
    q, q_dot, q_ddot = design.playable(loaded)[0].evaluate(t)
    generalized = reg.regressor(loaded, q, q_dot, q_ddot) @ reg.standard_parameters(loaded)
    forces = np.linalg.solve(np.swapaxes(leg_jacobian(loaded, q), 1, 2),
                             generalized[..., None])[..., 0]
    lengths = inverse_kinematics(loaded, q).lengths
    noise = SensorNoise(force_noise=170.0)
    predicted = predict_parameters(loaded, design, noise, payload=True, rate_hz=100.0,
                                   filtered=True)  # as the design's final prediction
    rng = np.random.default_rng(7)
    estimates, sections = [], []
    for _ in range(16):
        data = Dataset(t=t, pose=q, lengths=lengths, name="exp1",
                       forces=forces + rng.normal(0.0, noise.force_noise, forces.shape))
        fitted = PhysicalIdentifier(payload=True).fit([data], loaded)
        estimates.append([fitted.parameters_[n] for n in predicted.names])
        section = fitted.result_.diagnostics["payload"]
        sections.append([section["mass"], *section["com"], *section["inertia"]])
    observed = np.std(estimates, axis=0, ddof=1)
    ratio = predicted.expected_std_errors / observed
    # a spread over 16 seeds is uncertain by 1 / sqrt(30) = 18 % (one SE): the median over
    # the 24 parameters within 30 %, every one within a factor 2
    assert 0.7 < np.median(ratio) < 1.3, ratio
    assert np.all((ratio > 0.5) & (ratio < 2.0)), dict(zip(predicted.names, ratio, strict=True))
    # the Coulomb columns are sign functions whose reversals the kernel smooths: predicted
    # from the unfiltered regressor they came out 0.57-0.76 of their spread (median 0.65)
    coulomb = [k for k, name in enumerate(predicted.names) if name.startswith("coulomb")]
    assert 0.8 < np.median(ratio[coulomb]) < 1.3, ratio[coulomb]
    # the payload's mass, centre of mass and inertia about it, as the file holds them: the
    # covariance carried through the parallel-axis theorem against their spread
    sections = np.array(sections)
    quantities = predicted.payload_std_errors
    spread = {"mass": np.std(sections[:, 0], ddof=1) / PAYLOAD["mass"],
              "com": np.sqrt(np.linalg.eigvalsh(np.cov(sections[:, 1:4].T))[-1]),
              "inertia": np.std(sections[:, 4:], axis=0, ddof=1).max()
              / np.mean(PAYLOAD["inertia"][:3])}
    # the largest of 3 (com) or 6 (inertia) spreads runs high by up to a SE of 18 %
    assert all(0.6 < quantities[k] / spread[k] < 1.5 for k in spread), (quantities, spread)


def test_payload_quantities_and_their_derivative(loaded):
    """The payload's mass, centre of mass and inertia about it from its ten parameters
    about the reference point: the platform file's ``[payload]`` (which the platform turns
    into standard parameters by its own parallel-axis code) recovered; the derivative
    against central differences (error h^2 / 6 times the third derivative, which for
    h = 1e-4 of each parameter's size is below 1e-8 of the entries)."""
    body = reg.parameter_index(reg.BODY_PARAMETERS)
    total = reg.standard_parameters(loaded)[body]
    own = total - reg.standard_parameters(loaded.replace(payload=None))[body]
    m, c, inertia = reg.about_centre_of_mass(own)
    # the payload's share is the difference of two whole-body totals: its round-off is that
    # of the totals (eps times their size), allowed 64 times over
    ulp = 64 * np.finfo(float).eps
    assert abs(m - PAYLOAD["mass"]) <= ulp * total[0]
    assert np.allclose(c, PAYLOAD["com"], rtol=0, atol=ulp * np.abs(total[1:4]).max() / m)
    assert np.allclose(inertia, PAYLOAD["inertia"], rtol=0, atol=ulp * np.abs(total[4:]).max())
    J = payload_jacobian(own)

    def flat(body):
        m, c, inertia = reg.about_centre_of_mass(body)
        return np.hstack([[m], c, inertia])

    numeric = np.zeros((10, 10))
    for k in range(10):
        step = np.zeros(10)
        step[k] = 1e-4 * max(abs(own[k]), 1.0)
        numeric[:, k] = (flat(own + step) - flat(own - step)) / (2 * step[k])
    assert np.allclose(J, numeric, rtol=1e-6, atol=1e-8 * np.abs(numeric).max())


@pytest.mark.slow
def test_final_prediction_counts_the_pose_noise(loaded):
    """Rigid-body data of a record at twice the reference frequencies and half its amplitude,
    the leg lengths with the reference white noise (the pose from them by the first Newton
    step of forward kinematics), the forces with a tenth of it: the pose noise, through the
    filtered rates and accelerations, sets most parameters' spread, the friction's above
    all. Predicted from the force noise alone the errors came out 0.06-0.61 of the spread
    over 12 seeds (median 0.23, the friction's 0.06-0.19); with the pose noise's share
    0.69-1.46 (median 1.16). A 12-seed spread is itself uncertain by 21 %: the median within
    30 %, the friction's within a factor 2."""
    design = all_dofs_multisine(20.0, scale=0.5, slower=0.5)
    rate = loaded.sensors.sample_rate
    t = np.arange(int(20.0 * rate) + 1) / rate
    q, q_dot, q_ddot = design.playable(loaded)[0].evaluate(t)
    generalized = reg.regressor(loaded, q, q_dot, q_ddot) @ reg.standard_parameters(loaded)
    jacobian = leg_jacobian(loaded, q)
    forces = np.linalg.solve(np.swapaxes(jacobian, 1, 2), generalized[..., None])[..., 0]
    lengths = inverse_kinematics(loaded, q).lengths
    noise = SensorNoise(length_noise=2e-5, force_noise=17.0)
    predicted = predict_parameters(loaded, design, noise, payload=True, rate_hz=100.0,
                                   filtered=True)
    rng = np.random.default_rng(11)
    estimates = []
    for _ in range(12):
        error = rng.normal(0.0, noise.length_noise, lengths.shape)
        pose = q + np.linalg.solve(jacobian, error[..., None])[..., 0]
        data = Dataset(t=t, pose=pose, lengths=lengths + error, name="exp1",
                       forces=forces + rng.normal(0.0, noise.force_noise, forces.shape))
        fitted = PhysicalIdentifier(payload=True).fit([data], loaded)
        estimates.append([fitted.parameters_[n] for n in predicted.names])
    ratio = predicted.expected_std_errors / np.std(estimates, axis=0, ddof=1)
    named = dict(zip(predicted.names, ratio, strict=True))
    assert 0.7 < np.nanmedian(ratio) < 1.3, named
    friction = [k for k, name in enumerate(predicted.names)
                if name.startswith(("coulomb", "viscous")) and np.isfinite(ratio[k])]
    assert np.all((ratio[friction] > 0.5) & (ratio[friction] < 2.0)), named


def test_final_prediction_follows_the_motion_the_plant_played(loaded):
    """A plant that plays every record at 0.6 of its commanded amplitude, logged at 1 kHz:
    the prediction along its states (interpolated to the prediction's rate) is that of the
    design commanded at 0.6, within the interpolation of the 1 kHz samples (exact on the
    100 Hz grid), and differs from the commanded design's."""
    design = all_dofs_multisine(12.0)
    smaller = Design(tuple(r.scaled(0.6) for r in design.records))
    records = []
    for playable in smaller.playable(loaded):
        t = np.arange(int(12.0 * 1000) + 1) / 1000.0
        q, q_dot, q_ddot = playable.evaluate(t)
        records.append(SimpleNamespace(t=t, q=q, q_dot=q_dot, q_ddot=q_ddot))
    noise = SensorNoise(length_noise=2e-5, force_noise=170.0)
    states = played_states(records, design, 100.0)
    # the 100 Hz times fall on 1 kHz samples up to a few ulps of t (< 1e-14 s); each signal
    # changes by under 2 pi f_max (< 10) times its size per second: under 1e-13 of its size
    assert all(np.allclose(a, b, rtol=0, atol=1e-12 * max(1.0, np.abs(b).max()))
               for a, b in zip(states, design_rows(loaded, smaller, 100.0), strict=True))
    played = predict_parameters(loaded, design, noise, True, 100.0, states=states,
                                filtered=True)
    expected = predict_parameters(loaded, smaller, noise, True, 100.0, filtered=True)
    commanded = predict_parameters(loaded, design, noise, True, 100.0, filtered=True)
    assert np.allclose(played.std_errors, expected.std_errors, rtol=1e-9)
    assert played.worst_relative_std > 1.3 * commanded.worst_relative_std


def test_refinement_against_the_plant_scales_each_record_by_its_own(loaded):
    """A played design whose records the plant allowed 0.5 and 0.8 of: the scales read
    back, and every candidate of the refined search carries them, record by record, on
    top of its own commanded motion at the limits."""
    noise = SensorNoise(force_noise=170.0)
    first = candidate(loaded, 32.0, noise, True, np.zeros(8), 0.7)
    played = Design(tuple(r.scaled(k) for r, k in zip(first.design.records, (0.5, 0.8),
                                                      strict=True)))
    scales = plant_scales(first.design, played)
    assert np.allclose(scales, [0.5, 0.8], rtol=1e-12)
    refined = refine_for_plant(loaded, 32.0, noise, True, 0.7, np.zeros(8), scales,
                               evaluations=3)
    own = candidate(loaded, 32.0, noise, True, refined.parameters, 0.7).design
    ratio = [np.linalg.norm(r.amplitudes) / np.linalg.norm(o.amplitudes)
             for r, o in zip(refined.design.records, own.records, strict=True)]
    assert np.allclose(ratio, [0.5, 0.8], rtol=1e-9)
    # the smaller motion tells less: its prediction is worse than the unscaled candidate's
    assert refined.score > candidate(loaded, 32.0, noise, True, refined.parameters,
                                     0.7).score


@pytest.mark.slow
def test_payload_design_aims_at_the_accuracy_asked_for(loaded):
    """The same search asked for a centre of mass ten times tighter than the inertia, then
    the other way round: each pick's predicted standard error of what was asked more
    tightly is the smaller of the two picks' (0.96 against 1.57 mm, 0.30 against 0.47 %
    of the inertia)."""
    noise = SensorNoise(force_noise=170.0)
    picks = {}
    for tight, loose in (("com", "inertia"), ("inertia", "com")):
        accuracy = {"mass": 0.02, tight: 0.002, loose: 0.02}
        best = search_design(loaded, 32.0, noise, payload=True, random_candidates=8,
                             local_evaluations=40, accuracy=accuracy)
        assert best.prediction.accuracy == accuracy
        picks[tight] = best.prediction.payload_std_errors
    assert picks["com"]["com"] < picks["inertia"]["com"]
    assert picks["inertia"]["inertia"] < picks["com"]["inertia"]


@pytest.mark.slow
def test_payload_design_sharpens_the_ten_within_the_accuracy_margin(loaded, monkeypatch):
    """The search holds the payload's quantities within the margin of their accuracy and
    sharpens the ten parameters there: against a search of the same candidates judged on
    the quantities alone, its pick's worst relative standard error of the ten is smaller,
    while its quantities stay within the margin whenever that pick's do."""
    import stewartid.design.physical.search as search

    noise = SensorNoise(force_noise=170.0)
    kept = search_design(loaded, 32.0, noise, payload=True, random_candidates=8,
                         local_evaluations=40)
    monkeypatch.setattr(search, "design_objective", lambda prediction: prediction.criterion)
    alone = search_design(loaded, 32.0, noise, payload=True, random_candidates=8,
                          local_evaluations=40)
    assert kept.prediction.worst_relative_std < alone.prediction.worst_relative_std
    if held_share(alone.prediction.payload_std_errors, alone.prediction.accuracy)[0] <= 1:
        assert held_share(kept.prediction.payload_std_errors, kept.prediction.accuracy)[0] <= 1


def test_the_centre_of_mass_distance_quantile_matches_a_monte_carlo():
    """The distance a centre of mass's error stays within in 95 % of runs, from Satterthwaite's
    scaled chi-square, against 200 000 Gaussian draws (binomial SE of the share 0.0005): for
    equal axes it is the chi distribution's exact 2.795 standard errors; for unequal ones,
    within 1 %; the least certain axis's 1.96 standard errors would cover fewer runs."""
    rng = np.random.default_rng(7)
    assert distance_quantile(np.ones(3), 0.95) == pytest.approx(2.7955, abs=1e-4)
    for sd in ([0.34, 0.34, 0.67], [0.58, 0.78, 0.86], [0.1, 0.2, 1.0]):
        variances = np.square(sd)
        reach = distance_quantile(variances, 0.95)
        distance = np.linalg.norm(rng.normal(0.0, sd, (200_000, 3)), axis=1)
        assert abs(np.mean(distance <= reach) - 0.95) < 0.01
        assert np.mean(distance <= 1.96 * max(sd)) < 0.95
    assert distance_quantile(np.zeros(3), 0.95) == 0.0


def test_the_summary_says_whether_the_margin_was_held():
    """Within the margin the sentence says the ten were sharpened; beyond it, what lowers it
    (a 40 s design of a 1.2 t payload reached 0.67 of the accuracy)."""
    from stewartid.design.physical.workflow import criterion_summary

    needed = {"mass": 0.002, "com": 0.002, "inertia": 0.02}
    baseline = SimpleNamespace(criterion=0.8, worst_relative_std=0.5)
    for com, held in ((0.0006, True), (0.0008, False)):
        prediction = SimpleNamespace(
            payload=True, accuracy=needed, worst_relative_std=0.3, worst_parameter="payload.I_yy",
            payload_std_errors={"mass": 0.0004, "com": com, "com_distance": 2.8 * com,
                                "inertia": 0.004})
        text = criterion_summary(prediction, baseline)
        assert f"the largest share of its accuracy {com / 0.002:.3g} (com;" in text
        assert ("the search sharpened the ten parameters" in text) is held
        assert ("the centre of mass within its accuracy in fewer than the 95 % of runs"
                in text) is not held


def test_every_record_is_scaled_to_its_own_limit(loaded):
    """Records whose DOFs meet the pool's frequencies in another order reach the leg-speed
    limit at different amplitudes: each is scaled until its own motion, judged alone, uses
    the share asked for."""
    design = multisine_design(40.0, [0.2, 0.002, 0.002, 0.002, 0.002, 0.002])
    alone = [max(commanded_limit_use(loaded, Design((r,)))[0].peak.values())
             for r in design.records]
    assert abs(alone[0] / alone[1] - 1) > 0.1  # unequal before: one factor would not do
    scaled = scale_to_limits(loaded, design, 0.8)[0]
    for record in scaled.records:
        peak = max(commanded_limit_use(loaded, Design((record,)))[0].peak.values())
        assert peak == pytest.approx(0.8, rel=0.021)


def test_parameter_sizes_are_those_of_the_vector_and_the_tensor():
    """Worked by hand: mass 10 kg, first moment (3, -4, 0) kg m (length 5), inertia diagonal
    (1, 2, 6) kg m^2 (mean 3); every component of a group is judged against one size, so
    that turning the frame does not change the criterion. A centre of mass at the reference
    point falls back to a tenth of the mass times the radius of gyration sqrt(1.5 * 3 / 10)."""
    names = ("payload.m", "payload.mc_x", "payload.mc_y", "payload.mc_z", "payload.I_xx",
             "payload.I_yy", "payload.I_zz", "payload.I_xy", "payload.I_xz", "payload.I_yz",
             "viscous[actuator]")
    nominal = np.array([10.0, 3.0, -4.0, 0.0, 1.0, 2.0, 6.0, 0.0, -0.5, 0.1, 50.0])
    assert np.allclose(parameter_sizes(names, nominal), [10, 5, 5, 5, 3, 3, 3, 3, 3, 3, 0])
    nominal[1:4] = 0.0
    assert np.allclose(parameter_sizes(names, nominal)[1:4], 0.1 * 10 * np.sqrt(0.45))


@pytest.mark.slow
def test_physical_design_writes_commands_prediction_and_check(loaded, tmp_path):
    needed = {"mass": 0.003, "com": 0.001, "inertia": 0.02}
    out = run_physical_design(loaded, 16.0, SensorNoise(force_noise=170.0), tmp_path / "d",
                              payload=True, check_seeds=1,
                              search={"random_candidates": 2, "local_evaluations": 0,
                                      "plant_evaluations": 2}, accuracy=needed)
    document = json.loads((tmp_path / "d" / "design.json").read_text())
    assert document["model"] == "physical"
    for key in ("prediction", "prediction_commanded", "baseline"):
        judged = document[key]
        assert judged["required_accuracy"] == needed
        assert judged["criterion"] == pytest.approx(max(
            judged["payload_std_errors"][k] / needed[k] for k in needed), rel=1e-12)
    assert set(document["prediction"]["parameters"]) == set(document["baseline"]["parameters"])
    assert (set(document["prediction_commanded"]["parameters"])
            == set(document["prediction"]["parameters"]))
    assert all(max(peak.values()) <= 0.7 + 1e-3 for peak in document["limit_use"])
    assert document["identify"]["identify"].endswith("--model physical --payload")
    assert (tmp_path / "d" / "commands" / "exp1.csv").is_file()
    assert (tmp_path / "d" / "validation" / "validation.csv").is_file()
    assert out.check["seeds"] == 1 and out.check["ratio_median"] > 0
    # the report names the parameters whose fitted errors the prediction falls short of
    checked = document["check"]["parameters"]
    short = [n for n, v in checked.items()
             if v["reported"] is not None and v["reported"] > 1.5 * v["predicted"]]
    assert document["check"]["underpredicted"] == short
    report = (tmp_path / "d" / "report.md").read_text()
    assert "Along the commanded motion" in report
    assert ("Rely on the larger of the two" in report) == bool(short)


@pytest.mark.parametrize(("arguments", "message"), [
    (["--payload"], "--payload needs --model physical"),
    (["--model", "rigid"], "--model must be 'physical'"),
    (["--model", "physical", "--quick"], "--quick do not apply"),
    (["--model", "physical", "--payload"], "no [payload] section"),
    (["--model", "physical", "--seeds", "-1"], "--seeds must be >= 0"),
    (["--model", "physical", "--max-use", "1.5"], "--max-use must be"),
    (["--accuracy", "0.2,2,2"], "--accuracy needs --model physical"),
    (["--model", "physical", "--accuracy", "0.2,2,2"], "--accuracy applies to payload mode"),
    (["--model", "physical", "--payload", "--accuracy", "0.2,x,2"],
     "--accuracy must be three positive numbers"),
    (["--model", "physical", "--payload", "--accuracy", "0.2,2,0"],
     "--accuracy must be three positive numbers"),
])
def test_design_cli_refuses_bad_physical_options(tmp_path, arguments, message):
    result = CliRunner().invoke(app, ["design", "--out", str(tmp_path / "o"), *arguments])
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert len(result.output.strip().splitlines()) == 1, result.output

"""Runs at a stated accuracy (mjeap.simulation.accuracy): refusals, what a result carries, and the
claim itself against converged runs on cases drawn by a seeded generator."""
import json
import math

import numpy as np
import pytest

from mjeap import Scene
from mjeap.simulation.accuracy import ACCURACY_RANGE, ErrorModel, Model, check_accuracy
from mjeap.errors import ParameterError
from mjeap.simulation.rollout import rollout, rollout_batch
from mjeap.validation.accuracy_claim import check_case, draw_cases, summarise

FAST = dict(orientation="horizontal")          # pedot-micro horizontal, first mode 207 Hz


@pytest.mark.parametrize("bad", [0, 1.0, -1e-3, float("nan"), "tight", True, None, 1e-6])
def test_accuracy_outside_its_range_is_refused_naming_it(bad):
    if bad is None:
        assert Scene("pedot-micro").accuracy is None
        return
    with pytest.raises(ParameterError, match=r"accuracy=.*\[1e-05, 0\.2\]"):
        check_accuracy(bad)
    with pytest.raises(ParameterError, match="accuracy"):
        Scene("pedot-micro", accuracy=bad)


@pytest.mark.cable
def test_cable_scene_with_a_target_is_refused_before_any_run():
    s = Scene("pedot-micro", representation="cable", segments=6)
    with pytest.raises(ParameterError, match="cable"):
        rollout(s, "step:1V", 0.01, accuracy=1e-2)


def test_error_model_combines_in_quadrature():
    em = ErrorModel(spatial=0.16, temporal=100.0)
    assert em.predict(Model(4, 3e-4, "discrete")) == pytest.approx(math.hypot(0.01, 0.03))


def test_a_target_chooses_the_model_and_the_result_says_so(tmp_path):
    s = Scene("pedot-micro", accuracy=1e-2, **FAST)
    r = rollout(s, "square:1V@2Hz", 0.5, rrd=tmp_path / "a.rrd", csv_path=tmp_path / "a.csv")
    a = r.meta["accuracy"]
    assert a["target"] == 1e-2 and a["quantity"].startswith("tip curvature")
    assert a["estimated_error"] <= 1e-2 and a["met"]
    assert [x["role"] for x in a["runs"]][:3] == ["pilot"] * 3
    assert r.meta["scene"]["segments"] == a["model"]["segments"]
    assert r.meta["scene"]["timestep"] == pytest.approx(a["model"]["timestep"])
    assert s.layout.segments == 20 and s.time == 0.0            # the user's scene is left as it was
    from mjeap.io.recording import _meta_markdown
    assert "estimated_error" in _meta_markdown(r.meta)
    assert (tmp_path / "a.rrd").stat().st_size > 0 and (tmp_path / "a.csv").stat().st_size > 0


def test_a_chosen_discrete_step_may_exceed_the_fixed_rules_a_user_step_may_not():
    s = Scene("pedot-micro", orientation="up", payload="12.6mg@6.27mm")
    big = 8 * s.choice.rayleigh_beta
    with pytest.raises(ParameterError, match="timestep"):
        Scene("pedot-micro", orientation="up", payload="12.6mg@6.27mm", integrator="discrete", timestep=big)
    v = s.variant(8, big, "discrete")
    assert v.timestep == pytest.approx(big) and "accuracy target" in v.choice.reason
    assert np.all(v.model.jnt_stiffness >= 0) and np.all(v.model.dof_damping >= 0)


@pytest.mark.slow
def test_no_target_keeps_the_model_and_can_estimate_its_error():
    s = Scene("pedot-micro", **FAST)
    plain = rollout(s, "sine:1V@5Hz", 0.2)
    assert "accuracy" not in plain.meta
    r = rollout(s, "sine:1V@5Hz", 0.2, estimate_error=True)
    a = r.meta["accuracy"]
    assert a["target"] is None and a["model"]["segments"] == 20 and a["model"]["timestep"] == s.timestep
    assert 0 < a["estimated_error"] < 1e-2
    np.testing.assert_array_equal(r.tip_curvature, plain.tip_curvature)
    # against a converged run (40 segments at 1/8 of the step): within 3 x
    ref_scene = s.variant(40, s.timestep / 8, "discrete")
    from mjeap.simulation.accuracy import relative_difference
    from mjeap.drives import make_drive
    ref = rollout(ref_scene, "sine:1V@5Hz", 0.2, drive=make_drive(None, ref_scene),
                  sample_interval=float(r.time[1] - r.time[0]))
    true = relative_difference(ref, r)
    assert 1 / 3 <= a["estimated_error"] / true <= 3, (a["estimated_error"], true)


def test_batch_at_a_target_shares_one_model_and_estimates_each():
    s = Scene("pedot-micro", **FAST)
    rs = rollout_batch(s, ["sine:0.5V@5Hz", "sine:1.5V@5Hz"], 0.2, nthread=1, accuracy=3e-3)
    models = {json.dumps(r.meta["accuracy"]["model"], sort_keys=True) for r in rs}
    assert len(models) == 1
    assert all(r.meta["accuracy"]["estimated_error"] <= 3e-3 for r in rs)


def test_batch_pilots_run_on_its_first_member_and_each_member_is_measured(monkeypatch):
    """The pilots run once, on the first member; the segments' error of every member is then
    measured on it (a companion of N / sqrt 2 segments), not taken from the pilots' a."""
    from mjeap import rollout_batch
    from mjeap.simulation import pipeline
    sizes = []
    real = pipeline.run

    def counting(job):          # the model runs come back through the pipeline's one entry
        if job.batch and job.accuracy is None and job.target.chosen_model:
            sizes.append(len(job.waves))
        return real(job)
    monkeypatch.setattr(pipeline, "run", counting)
    s = Scene("pedot-micro", **FAST)
    rs = rollout_batch(s, ["sine:0.5V@5Hz", "sine:1.0V@5Hz", "sine:1.5V@5Hz"], 0.2, nthread=1, accuracy=3e-3)
    roles = [x["role"] for x in rs[0].meta["accuracy"]["runs"]]
    assert roles.count("pilot") == 3 and "spatial companion" in roles
    assert sizes[:3] == [1, 1, 1] and all(n == 3 for n in sizes[3:])
    assert "first member" in rs[0].meta["accuracy"]["error_model"]["pilots"]
    assert len({r.meta["accuracy"]["estimated_error"] for r in rs}) == 3       # each member its own


def test_cli_refuses_a_timestep_beside_a_target(capsys):
    from mjeap.cli import main
    rc = main(["rollout", "pedot-micro", "--voltage", "step:1V", "--duration", "0.01", "--accuracy", "1e-2",
               "--timestep", "1e-5"])
    assert rc != 0
    assert "--timestep" in capsys.readouterr().err


@pytest.mark.slow
def test_the_accuracy_claim_on_seeded_cases():
    """True error (against 2 x the segments at 1/4 of the step) below the target in at
    least 95 % of cases (here: all), never above 2 x; the estimate within 3 x of it in at
    least 90 % (10 of these 11; 23 of 24 with the next 13, scripts/bench.py: the one
    outlier, a piezo sine at 1.8e-4, is estimated 3.9 x high)."""
    rows = [check_case(c) for c in draw_cases(seed=23, n=11)]
    s = summarise(rows)
    detail = "\n".join(f"{r['case']}: true {r['true_error']:.3g}, estimate {r['estimated_error']:.3g}" for r in rows)
    assert s["below_target"] >= 0.95, detail
    assert s["worst_true_over_target"] <= 2.0, detail
    assert s["estimate_within_3x"] >= 0.9, detail
    assert s["estimate_over_true_range"][0] >= 1 / 3, detail         # never an estimate 3 x too low
    assert ACCURACY_RANGE[0] <= min(r["target"] for r in rows)


class _Run:
    def __init__(self, kappa):
        self.tip_curvature = np.asarray(kappa, float)
        self.time = np.arange(len(kappa)) * 1e-3


def test_the_spatial_error_is_richardson_of_order_2():
    """kappa_N = kappa + c / N^2 (order 2 exactly): spatial_error of N against n segments is
    max |c| / N^2 over the swing, whatever n."""
    from mjeap.simulation.accuracy import fewer_segments, spatial_error
    t = np.linspace(0, 1, 201)
    exact, c = np.sin(2 * np.pi * t), 0.3 * np.cos(5 * t)
    for N in (7, 20, 41):
        n = fewer_segments(N)
        assert 2 <= n < N
        e = spatial_error(_Run(exact + c / N**2), _Run(exact + c / n**2), N, n)
        assert e == pytest.approx(np.max(np.abs(c)) / N**2 / np.ptp(exact + c / N**2), rel=1e-12)


@pytest.mark.slow
def test_a_given_error_model_replaces_the_pilots_and_the_error_is_still_measured():
    """A prior (a, b) from elsewhere only chooses the first model: the run has no pilots, the
    segments' error is measured on the question (a spatial companion). Priors 4 x off the
    question's own pilots in opposite directions, (4 a, b / 4) and (a / 4, 4 b), choose other
    models than the pilots do; the true error (against 40 segments at 1/4 of the finest step,
    discrete) stays below the target and the estimate within 3 x of it (measured: 0.38 x for
    (4 a, b / 4), the shared path's estimate leaning low where Richardson's step part does;
    1.3 x and 1.4 x the others). A spatial estimate of zero would give 0.33 x there."""
    from mjeap.drives import make_drive
    from mjeap.simulation.accuracy import relative_difference
    s = Scene("pedot-micro", **FAST)
    wave, T, target, every = "sine:1V@5Hz", 0.2, 3e-4, 1e-3
    own = rollout(s, wave, T, accuracy=target, sample_interval=every)
    a, b = own.meta["accuracy"]["error_model"]["spatial_a"], own.meta["accuracy"]["error_model"]["temporal_b_per_s"]
    runs = [own] + [rollout(s, wave, T, accuracy=target, error_model=p, sample_interval=every)
                    for p in ((4 * a, b / 4), (a / 4, 4 * b))]
    first = [[x for x in r.meta["accuracy"]["runs"] if x["role"] == "chosen"][0] for r in runs]
    assert {(x["segments"], x["timestep"]) for x in first[1:]} != {(first[0]["segments"], first[0]["timestep"])}
    h = min(r.meta["accuracy"]["model"]["timestep"] for r in runs) / 4
    ref_scene = s.variant(40, h, "discrete")
    ref = rollout(ref_scene, wave, T, drive=make_drive(None, ref_scene), sample_interval=every)
    for r in runs[1:]:
        acc = r.meta["accuracy"]
        roles = [x["role"] for x in acc["runs"]]
        assert "pilot" not in roles and "spatial companion" in roles
        assert "given" in acc["error_model"]["pilots"]
    for r in runs:
        true, est = relative_difference(ref, r), r.meta["accuracy"]["estimated_error"]
        assert true <= target, (r.meta["accuracy"]["model"], true)
        assert 1 / 3 <= est / true <= 3, (r.meta["accuracy"]["model"], true, est)


def test_a_prior_beyond_the_step_budget_falls_back_to_the_pilots():
    s = Scene("pedot-micro", **FAST)
    r = rollout(s, "sine:1V@5Hz", 0.2, accuracy=3e-3, error_model=(4e-4, 1e7))
    roles = [x["role"] for x in r.meta["accuracy"]["runs"]]
    assert roles[:3] == ["pilot"] * 3 and r.meta["accuracy"]["estimated_error"] <= 3e-3


@pytest.mark.parametrize("bad", [(-1.0, 1.0), (1.0, float("nan")), "ab", 3.0])
def test_a_bad_error_model_is_refused_naming_it(bad):
    with pytest.raises(ParameterError, match="error_model"):
        rollout(Scene("pedot-micro", **FAST), "step:1V", 0.01, accuracy=1e-2, error_model=bad)


def test_an_error_model_without_a_target_is_refused():
    with pytest.raises(ParameterError, match="error_model"):
        rollout(Scene("pedot-micro", **FAST), "step:1V", 0.01, error_model=(0.1, 1.0))


@pytest.mark.slow
def test_the_claim_with_shared_priors_on_seeded_cases():
    """The first 6 of the seeded claim's cases (seed 23), each also run from priors 4 x off
    its own pilots' constants either way, (4 a, b / 4) and (a / 4, 4 b), as a sweep's family
    shares them: the true error below the target in every run and the estimate never 3 x too
    low. Measured on all 11 cases: true error at most 0.55 x the target; estimate 0.82 to
    4.6 x (4 a, b / 4) and 0.82 to 5.5 x (a / 4, 4 b) the true error, within 3 x in 9 and 10
    of 11: the shared path errs high, over-resolving, where its priors are pessimistic."""
    rows = []
    for case in draw_cases(seed=23, n=6):
        a, b = check_case(case)["error_model"]
        rows += [check_case(case, error_model=p) for p in ((4 * a, b / 4), (a / 4, 4 * b))]
    s = summarise(rows)
    detail = "\n".join(f"{r['case']}: true {r['true_error']:.3g}, estimate {r['estimated_error']:.3g}" for r in rows)
    assert s["below_target"] == 1.0, detail
    assert s["estimate_over_true_range"][0] >= 1 / 3, detail


def test_a_target_keeps_the_scenes_tip_loads_and_meets_the_elastica():
    """The models a target runs are variants of the scene: they carry its tip force (they
    once ran unloaded, "error 0", 4 segments). Reference: the elastica of a dead tip force
    P L^2 / EI = 1 (mjeap.analytical, a BVP), settled (first-mode damping ratio 0.7)."""
    from mjeap import analytical as an
    s = Scene("pedot-micro", gravity=False, damping_ratio=0.7)
    L, EI = s.length, float(s.flexural_rigidity(0.0))
    s.set_tip_force(EI / L**2)
    ref = an.elastica_tip_force(EI / L**2, L, EI).tip
    r = rollout(s, "step:0V", 0.05, drive="none", accuracy=1e-2)
    a = r.meta["accuracy"]
    assert a["met"] and 0 < a["error_model"]["spatial_a"]
    assert np.all(r.tip_position[-1, :2] > 0)
    # the tip within 1 % of the deflection (the chosen model's own error, not a tuned one)
    assert abs(r.tip_position[-1, 1] / ref[1] - 1) < 1e-2, (r.tip_position[-1], ref, a["model"])
    v = s.variant(8, s.timestep, "implicitfast")
    np.testing.assert_allclose(v.part.tip_loads()[0], [0.0, EI / L**2, 0.0], rtol=1e-12, atol=1e-20)


def test_hinge_parameters_set_by_hand_refuse_a_target_or_an_estimate():
    s = Scene("pedot-micro", **FAST)
    s.set_hinge_parameters(stiffness=s.layout.hinge_stiffness * 1.1)
    for kw in (dict(accuracy=1e-2), dict(estimate_error=True)):
        with pytest.raises(ParameterError, match="set_hinge_parameters"):
            rollout(s, "sine:1V@5Hz", 0.1, **kw)
        assert s.time == 0.0                       # refused before any run
    with pytest.raises(ParameterError, match="set_hinge_parameters"):
        rollout_batch(s, ["sine:1V@5Hz"], 0.1, accuracy=1e-2)

"""Support motions: closed-form velocities of every kind, record files, validation messages."""

from __future__ import annotations

import dataclasses
import math
import pickle
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid, quad

from masonrycli.errors import InputError
from masonrycli.records.motion import Record
from masonrycli.records.read import record_motion
from masonrycli.scenario.motion import Constant, Fixed, Ramp, Sine, support_velocity
from masonrycli.scenario.toml_bodies import MOTION_KINDS

DATA = Path(__file__).parent / "data"
T = np.linspace(-0.5, 3.0, 1401)


def one_line(exc_info) -> str:
    msg = str(exc_info.value)
    assert "\n" not in msg and msg.strip() == msg and msg
    return msg


# ---------------------------------------------------------------------------------------------- kinds


def test_fixed_is_zero():
    v = support_velocity([Fixed()], T)
    assert v.shape == (T.size, 1, 2)
    assert np.all(v == 0.0)
    assert Fixed().role == "fixed"


def test_constant_velocity_settlement():
    m = Constant(velocity=[0.0, -0.01])
    v = support_velocity([m], T)
    assert np.all(v[:, 0, 0] == 0.0) and np.all(v[:, 0, 1] == -0.01)
    assert m.role == "driven"
    assert m.velocity == (0.0, -0.01)  # normalised to a tuple of floats


def test_sine_closed_form_along_normalised_direction():
    m = Sine(direction=(3.0, 4.0), amplitude=1.5, frequency=2.0, phase=0.3)
    v = support_velocity([m], T)[:, 0, :]
    s = 1.5 * np.sin(2 * np.pi * 2.0 * T + 0.3)
    np.testing.assert_allclose(v[:, 0], 0.6 * s, rtol=0, atol=1e-15)
    np.testing.assert_allclose(v[:, 1], 0.8 * s, rtol=0, atol=1e-15)
    assert m.direction == (3.0, 4.0)  # stored as given, normalised on use


def test_sine_paper_ground():
    m = Sine(amplitude=1.0, frequency=2.0)  # default direction: horizontal
    t = np.array([0.0, 0.125, 0.25, 0.375])
    np.testing.assert_allclose(m.velocity_at(t)[:, 0], [0.0, 1.0, 0.0, -1.0], atol=1e-15)
    assert np.all(m.velocity_at(t)[:, 1] == 0.0)


def test_ramp_pulse_and_unbounded_ramp():
    pulse = Ramp(acceleration=(2.0, -1.0), until=0.5)
    ramp = Ramp(acceleration=(0.0, 3.0))
    v = support_velocity([pulse, ramp], T)
    tc = np.clip(T, 0.0, 0.5)
    np.testing.assert_allclose(v[:, 0, 0], 2.0 * tc, atol=1e-15)
    np.testing.assert_allclose(v[:, 0, 1], -1.0 * tc, atol=1e-15)
    np.testing.assert_allclose(v[:, 1, 1], 3.0 * np.clip(T, 0.0, None), atol=1e-15)
    assert np.all(v[:, 1, 0] == 0.0)


def test_support_velocity_shapes():
    assert support_velocity([], T).shape == (T.size, 0, 2)
    assert support_velocity([Constant(velocity=(1, 2))], 0.25).shape == (1, 1, 2)
    with pytest.raises(ValueError):
        support_velocity([Fixed()], np.zeros((2, 2)))


def test_support_velocity_order_follows_supports():
    ms = [Constant(velocity=(float(i), -float(i))) for i in range(4)]
    v = support_velocity(ms, np.array([0.0, 1.0]))
    assert v.shape == (2, 4, 2)
    for i in range(4):
        assert np.all(v[:, i, 0] == i) and np.all(v[:, i, 1] == -i)


def test_support_velocity_is_vectorised_over_time():
    # a long record evaluated at a million instants must not loop over them in Python
    import time

    rng = np.random.default_rng(0)
    t_rec = np.cumsum(rng.uniform(0.005, 0.015, 2000))
    m = Record(time=tuple(t_rec), value=tuple(rng.normal(size=2000)), quantity="acceleration")
    t = np.linspace(0, t_rec[-1] + 1, 1_000_000)
    start = time.perf_counter()
    v = support_velocity([m, Sine(amplitude=1, frequency=2), Fixed()], t)
    assert time.perf_counter() - start < 5.0  # a Python loop over 1e6 samples would take far longer
    assert v.shape == (t.size, 3, 2) and np.all(np.isfinite(v))


# -------------------------------------------------------------------------------------------- records


def test_velocity_record_interpolates_and_holds_end_values():
    m = Record(time=(0.1, 0.2, 0.4), value=(1.0, 3.0, -1.0), direction=(0.0, 2.0), scale=0.5)
    t = np.array([0.0, 0.1, 0.15, 0.2, 0.3, 0.4, 5.0])
    expected = 0.5 * np.array([1.0, 1.0, 2.0, 3.0, 1.0, -1.0, -1.0])
    v = m.velocity_at(t)
    np.testing.assert_allclose(v[:, 1], expected, atol=1e-15)
    assert np.all(v[:, 0] == 0.0)


def test_vector_record_three_columns():
    m = record_motion(DATA / "ground_xy.csv")
    assert m.is_vector and m.quantity == "velocity"
    v = m.velocity_at([0.0, 0.25, 0.5, 0.75, 1.0, 2.0])
    np.testing.assert_allclose(v[:, 0], [0.0, 0.05, 0.1, 0.05, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(v[:, 1], [0.0, -0.01, -0.02, -0.01, 0.0, 0.0], atol=1e-15)


def test_constant_acceleration_record_integrates_to_a_t():
    m = record_motion(DATA / "accel_constant.csv", quantity="acceleration", direction=(0.0, 1.0), baseline="none")
    t = np.linspace(-0.2, 1.5, 171)
    v = m.velocity_at(t)
    np.testing.assert_allclose(v[:, 1], 0.5 * np.clip(t, 0.0, 1.0), rtol=0, atol=1e-14)
    assert np.all(v[:, 0] == 0.0)


def test_linear_acceleration_record_integrates_exactly_between_samples():
    # a(t) = c t sampled every 0.25 s: v(t) = c t^2 / 2 everywhere, not only at the samples
    c = 1.7
    times = np.arange(0.0, 2.0001, 0.25)
    m = Record(time=tuple(times), value=tuple(c * times), quantity="acceleration", baseline="none")
    t = np.linspace(0.0, 2.0, 801)
    np.testing.assert_allclose(m.velocity_at(t)[:, 0], c * t**2 / 2, rtol=0, atol=1e-13)
    # after the record the acceleration is zero: the velocity holds its final value
    np.testing.assert_allclose(m.velocity_at([3.0])[0, 0], c * 2.0**2 / 2, rtol=1e-14)


def test_random_acceleration_record_matches_independent_integration():
    rng = np.random.default_rng(1)
    times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.01, 0.05, 60))])
    acc = rng.normal(size=(times.size, 2))
    m = Record(
        time=tuple(times),
        value=tuple(map(tuple, acc)),
        quantity="acceleration",
        baseline="none",
        scale=-2.0,
    )
    # at the samples: the cumulative trapezoid rule (scipy's, independent of ours)
    nodal = -2.0 * cumulative_trapezoid(acc, times, axis=0, initial=0.0)
    np.testing.assert_allclose(m.velocity_at(times), nodal, rtol=0, atol=1e-12)
    # between samples: the integral of the linearly interpolated acceleration (adaptive quadrature)
    for tq in rng.uniform(times[0], times[-1], 5):
        for k in range(2):
            ref, _ = quad(
                lambda s, k=k: -2.0 * np.interp(s, times, acc[:, k]),
                0.0,
                tq,
                points=times[times < tq],
                limit=200,
                epsabs=1e-13,
            )
            assert m.velocity_at([tq])[0, k] == pytest.approx(ref, abs=1e-10)
    # before the first sample: at rest
    assert np.all(m.velocity_at([-1.0]) == 0.0)


def test_acceleration_record_starting_late_is_at_rest_before():
    m = Record(time=(1.0, 2.0), value=(2.0, 2.0), quantity="acceleration", baseline="none")
    np.testing.assert_allclose(m.velocity_at([0.0, 1.0, 1.5, 2.0, 9.0])[:, 0], [0, 0, 1.0, 2.0, 2.0], atol=1e-15)


# ------------------------------------------------------------------------------------------ validation


@pytest.mark.parametrize(
    "kwargs, expected",
    [
        (dict(kind="sine", direction=(0, 0), amplitude=1), "direction = [0.0, 0.0]: must not be the zero vector"),
        (dict(kind="sine", direction=(1,)), "direction = [1]: must be 2 numbers"),
        (dict(kind="sine", amplitude=math.nan), "amplitude = nan: must be a finite number"),
        (dict(kind="sine", frequency=-1.0), "frequency = -1.0: must be >= 0"),
        (dict(kind="sine", phase=math.inf), "phase = inf: must be a finite number"),
        (dict(kind="constant", velocity=(1.0, math.inf)), "velocity = [1.0, inf]: must be finite numbers"),
        (dict(kind="ramp", acceleration=(1, 0), until=0.0), "until = 0.0: must be > 0"),
        (dict(kind="record", time=(0.0,), value=(1.0,)), "a record needs at least 2 samples"),
        (dict(kind="record", time=(0.0, 1.0), value=(1.0,)), "value = [1.0]: has 1 samples"),
        (dict(kind="record", time=(0.0, 0.0), value=(1.0, 2.0)), "time[1] = 0.0: must be >"),
        (
            dict(kind="record", time=(0, 1), value=(1, 2), quantity="displacement"),
            'quantity = "displacement": must be "velocity" or "acceleration"',
        ),
        (dict(kind="record", time=(0, 1), value=(1, 2), scale="2"), 'scale = "2": must be a number'),
        (dict(kind="sine", amplitude=True), "amplitude = true: must be a number"),
    ],
)
def test_motion_validation(kwargs, expected):
    cls = MOTION_KINDS[kwargs.pop("kind")]
    with pytest.raises(InputError) as exc:
        cls(**kwargs)
    assert expected in one_line(exc)


def test_motion_equality_hash_and_describe():
    a = Sine(direction=[1, 0], amplitude=1, frequency=2)
    b = Sine(direction=(1.0, 0.0), amplitude=1.0, frequency=2.0)
    assert a == b and hash(a) == hash(b)
    assert a.describe() == "sine 1 m/s · sin(2π·2 Hz·t) along (1, 0)"
    assert Ramp(acceleration=(0, -1), until=0.2).describe() == "ramp acceleration (0, -1) m/s² until 0.2 s"
    assert Constant(velocity=(0, -0.01)).describe() == "constant velocity (0, -0.01) m/s"


def test_baseline_correction_is_the_smallest_quadratic_that_returns_the_ground():
    # a random acceleration record drifts; corrected, it ends at rest where it started, and the
    # correction is a polynomial c1 s + c2 s^2 (s = t/T) in the velocity, checked by an independent fit
    rng = np.random.default_rng(4)
    times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.01, 0.03, 80))])
    acc = rng.normal(size=times.size) + 0.3
    raw = Record(time=tuple(times), value=tuple(acc), quantity="acceleration", baseline="none")
    cor = Record(time=tuple(times), value=tuple(acc), quantity="acceleration")
    t = np.linspace(0.0, times[-1], 20_001)
    diff = raw.velocity_at(t)[:, 0] - cor.velocity_at(t)[:, 0]
    s = t / times[-1]
    coef, *_ = np.linalg.lstsq(np.stack([s, s * s], axis=1), diff, rcond=None)
    np.testing.assert_allclose(diff, coef[0] * s + coef[1] * s * s, atol=1e-12)
    c = cor.baseline_correction
    np.testing.assert_allclose(coef, [c["c1"][0], c["c2"][0]], rtol=1e-9)
    assert abs(cor.velocity_at([times[-1], times[-1] + 5.0])[:, 0]).max() < 1e-12  # at rest after
    displacement, _ = quad(lambda x: cor.velocity_at([x])[0, 0], 0.0, times[-1], points=times[1:-1], limit=500)
    assert abs(displacement) < 1e-10
    assert abs(quad(lambda x: raw.velocity_at([x])[0, 0], 0.0, times[-1], points=times[1:-1], limit=500)[0]) > 0.1
    assert "baseline-corrected" in cor.describe() and "baseline" not in raw.describe()
    assert Record(time=(0, 1), value=(1, 2)).baseline_correction == {"baseline": "none"}  # velocity records


def test_record_window_and_baseline_validation():
    with pytest.raises(InputError, match="window = \\[0.5, 0.6\\]: holds 0 samples"):
        Record(time=(0, 1), value=(1, 2), window=(0.5, 0.6))
    with pytest.raises(InputError, match="window = \\[1.0, 0.0\\]: must be \\[start, end\\]"):
        Record(time=(0, 1), value=(1, 2), window=(1, 0))
    with pytest.raises(InputError, match='baseline = "linear": must be "quadratic" or "none"'):
        Record(time=(0, 1), value=(1, 2), baseline="linear")


def test_a_record_of_floats_is_checked_at_once_with_the_same_messages():
    # a record file's samples (Python floats) are checked with numpy: 3 million check_real calls took 7 s.
    # The same record given with ints (checked item by item) is the reference.
    n = 100_001
    t = [i * 0.01 for i in range(n)]
    v = [math.sin(x) for x in t]
    fast = Record(time=tuple(t), value=tuple(v), window=(1.0, 2.0))
    slow = Record(time=(0, *t[1:]), value=(0, *v[1:]), window=(1, 2))
    assert fast == slow and fast.time.dtype == np.float64 and fast._arrays[0].size == 101
    pairs = Record(time=tuple(t), value=tuple(zip(v, v)))
    assert pairs.value.tolist() == [[float(x), float(x)] for x in v] and pairs.is_vector
    for k, bad, message in [
        (70_000, "time", "time[70000] = 699.99: must be > the previous time 699.99"),
        (90_000, "nan", "time[90000] = nan: must be a finite number"),
        (80_000, "value", "value[80000] = inf: must be a finite number"),
        (60_000, "pair", "value[60000] = [0.5, nan]: must be finite"),
    ]:
        tt, vv = list(t), list(v) if bad != "pair" else list(zip(v, v))
        if bad == "time":
            tt[k] = tt[k - 1]
        elif bad == "nan":
            tt[k] = math.nan
        elif bad == "value":
            vv[k] = math.inf
        else:
            vv[k] = (0.5, math.nan)
        with pytest.raises(InputError) as exc:
            Record(time=tuple(tt), value=tuple(vv))
        assert message in one_line(exc)


def test_a_record_holds_read_only_float64_arrays():
    # a 3-million-sample record built Python tuples of its samples: 0.7 s before the run began
    t, v = np.arange(5) * 0.1, np.array([0.0, 1.0, -1.0, 0.5, 0.0])
    m = Record(time=t, value=v)
    assert m.time.dtype == m.value.dtype == np.float64 and m.time.shape == m.value.shape == (5,)
    assert not m.time.flags.writeable and not m.value.flags.writeable
    t[1] = 99.0  # the caller's arrays were copied: the record does not change with them
    assert m.time[1] == 0.1 and t.flags.writeable
    with pytest.raises(ValueError):
        m.value[0] = 1.0
    again = dataclasses.replace(m, scale=2.0)  # a study's scale axis: the samples are shared, not copied
    assert again.time is m.time and again.value is m.value
    pairs = Record(time=[0, 1, 2], value=np.array([[1, 2], [3, 4], [5, 6]], dtype=np.float32))
    assert pairs.is_vector and pairs.value.dtype == np.float64 and pairs.value.tolist() == [[1, 2], [3, 4], [5, 6]]


def test_records_compare_hash_and_pickle_by_their_samples():
    m = Record(time=(0.0, 0.1, 0.2), value=(1.0, 2.0, 3.0), quantity="acceleration", window=(0.0, 0.15))
    same = Record(time=[0, 0.1, 0.2], value=np.array([1, 2, 3]), quantity="acceleration", window=(0, 0.15))
    assert m == same and hash(m) == hash(same) and len({m, same}) == 1
    assert m != dataclasses.replace(m, value=(1.0, 2.0, 3.5))
    assert m != dataclasses.replace(m, time=(0.0, 0.1, 0.25))
    assert m != dataclasses.replace(m, baseline="none")
    assert m != Record(time=(0.0, 0.1, 0.2), value=((1.0, 1.0), (2.0, 2.0), (3.0, 3.0)), quantity="acceleration")
    assert m != Sine(amplitude=1.0, frequency=1.0) and m != "record"
    m.velocity_at([0.05])  # fills the cache of prepared arrays, which a pickle leaves out (it is rebuilt)
    back = pickle.loads(pickle.dumps(m))
    assert back == m and "_arrays" not in back.__dict__ and len(pickle.dumps(m)) < 1000
    assert not back.time.flags.writeable and not back.value.flags.writeable
    assert back.velocity_at([0.05, 0.3]).tobytes() == m.velocity_at([0.05, 0.3]).tobytes()


def test_a_record_time_step_spaces_its_times():
    m = Record(time=np.arange(4) * 0.02, value=(0.0, 1.0, 0.0, -1.0), time_step=0.02)
    assert m.time_step == 0.02 and "4 samples every 0.02 s, 0–0.06 s" in m.describe()
    with pytest.raises(InputError) as exc:
        Record(time=(0.0, 0.02, 0.05), value=(0.0, 1.0, 0.0), time_step=0.02)
    assert one_line(exc) == "time_step = 0.02: the times are not 0, time_step, 2 time_step, ..."
    for bad, problem in [(0, "must be > 0"), (math.nan, "must be a finite number"), (2.0, "must be within 1e-06–1 s")]:
        with pytest.raises(InputError) as exc:
            Record(time=(0.0, 1.0), value=(0.0, 1.0), time_step=bad)
        assert problem in one_line(exc)

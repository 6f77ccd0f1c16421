"""lash.DeadzoneInverse / lash.BacklashInverse: inverse then nonlinearity is the identity on random
signals, checked against independent numpy implementations of the deadzone and the backlash
(docs/compensation.md, the definitions in include/lash/blocks/*_inverse.hpp)."""
import numpy as np
import pytest

import lash


def deadzone(v, c_r, c_l, m_r=1.0, m_l=1.0):
    """DZ(v) = m_r (v - c_r) for v > c_r, 0 for -c_l <= v <= c_r, m_l (v + c_l) for v < -c_l (numpy)."""
    v = np.asarray(v, dtype=float)
    return np.where(v > c_r, m_r * (v - c_r), np.where(v < -c_l, m_l * (v + c_l), 0.0))


def backlash(w, c_r, c_l, y0=0.0):
    """y(k) = w - c_r if w > y(k-1) + c_r, w + c_l if w < y(k-1) - c_l, else y(k-1) (plain loop)."""
    y = np.empty(len(w))
    prev = y0
    for k, wk in enumerate(w):
        if wk > prev + c_r:
            prev = wk - c_r
        elif wk < prev - c_l:
            prev = wk + c_l
        y[k] = prev
    return y


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_deadzone_inverse_is_identity(seed):
    rng = np.random.default_rng(seed)
    c_r, c_l, m_r, m_l = rng.uniform(0.1, 300, 2).tolist() + rng.uniform(0.2, 5, 2).tolist()
    u = rng.normal(0, 100, 20000)
    u[::97] = 0.0
    di = lash.DeadzoneInverse(c_r, c_l, slope_right=m_r, slope_left=m_l)
    v = di.apply(u)
    np.testing.assert_allclose(deadzone(v, c_r, c_l, m_r, m_l), u, rtol=1e-12, atol=1e-9)
    # the command jumps over the deadzone: never inside it except at u = 0
    assert np.all((v > c_r) | (v < -c_l) | (u == 0))
    # apply == step sample by sample, bit for bit; lists and ints are converted
    assert np.array_equal(v, [di.step(x) for x in u])
    assert np.array_equal(di.apply([0, 1, -1]), [0.0, c_r + 1 / m_r, -c_l - 1 / m_l])


def test_deadzone_inverse_smoothing_bounded():
    rng = np.random.default_rng(5)
    u = rng.normal(0, 3, 5000)
    d = 2.0
    di = lash.DeadzoneInverse(10.0, 20.0, smoothing=d)
    err = deadzone(di.apply(u), 10.0, 20.0) - u
    assert np.all(np.abs(err) <= np.minimum(np.abs(u), d) + 1e-12)
    assert np.all(err[np.abs(u) >= d] == pytest.approx(0.0, abs=1e-12))
    assert np.max(np.abs(err)) > 0.1  # the band really acts


def test_deadzone_set_params():
    di = lash.DeadzoneInverse(1.0, 2.0)
    di.set_params(right=5.0)
    assert di.params == dict(right=5.0, left=2.0, slope_right=1.0, slope_left=1.0, smoothing=0.0)
    assert di.step(1.0) == 6.0 and di.step(-1.0) == -3.0
    di.set_params(slope_left=-1.0)  # outside its domain: kept
    assert di.params["slope_left"] == 1.0


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_backlash_inverse_is_identity(seed):
    rng = np.random.default_rng(seed)
    c_r, c_l = rng.uniform(0.05, 2.0, 2)
    # random walk with holds and reversals
    du = rng.normal(0, 0.3, 20000)
    du[rng.random(20000) < 0.2] = 0.0
    u = np.cumsum(du)
    bi = lash.BacklashInverse(c_r, c_l)
    bi.reset(u[0])
    w = bi.apply(u)
    np.testing.assert_allclose(backlash(w, c_r, c_l, y0=u[0]), u, rtol=0, atol=1e-9 * (1 + np.abs(u).max()))
    bi.reset(u[0])
    assert np.array_equal(w, [bi.step(x) for x in u])
    o = w - u  # the offset sits at one end of the gap
    assert np.all(np.minimum(np.abs(o - c_r), np.abs(o + c_l)) < 1e-9 * (1 + np.abs(u).max()))


def test_backlash_inverse_smoothing_and_params():
    rng = np.random.default_rng(9)
    u = np.cumsum(rng.normal(0, 0.05, 5000))
    bi = lash.BacklashInverse(0.5, 0.5, smoothing=0.2)
    bi.reset(u[0])
    w = bi.apply(u)
    err = backlash(w, 0.5, 0.5, y0=u[0]) - u
    assert np.max(np.abs(err)) <= 0.2 + 1e-12 and np.max(np.abs(err)) > 0.0
    bi = lash.BacklashInverse(1.0, 1.0)
    assert bi.offset == 1.0
    bi.set_params(right=2.0)
    assert bi.offset == 2.0 and bi.params == dict(right=2.0, left=1.0, smoothing=0.0)


def test_bad_parameters():
    with pytest.raises(lash.InputError):
        lash.DeadzoneInverse(-1.0, 1.0)
    with pytest.raises(lash.InputError):
        lash.DeadzoneInverse(1.0, 1.0, slope_right=0.0)
    with pytest.raises(lash.InputError):
        lash.BacklashInverse(1.0, float("nan"))
    with pytest.raises(ValueError):
        lash.DeadzoneInverse(1.0, 1.0).apply(np.zeros((2, 2)))

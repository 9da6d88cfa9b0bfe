"""SCG (docs/method.md §8.6, §11 item 9) on problems with known answers."""

import math

import numpy as np
import pytest
import torch
from numpy.testing import assert_allclose

from skgesture.utils._scg import SCG

SIGMA_GT = 5.0e-5  # docs/method.md §8.6.1
LAMBDA_GT = 5.0e-7  # docs/method.md §8.6.1
ROSENBROCK_START = (-1.2, 1.0)
ROSENBROCK_MIN = np.array([1.0, 1.0])


# --------------------------------------------------------------------- problems
def _quadratic(n, seed):
    """Well-conditioned SPD ``A`` (eigenvalues 1..4), ``b`` and ``A^-1 b``."""
    rng = np.random.default_rng(seed)
    q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    a = q @ np.diag(np.linspace(1.0, 4.0, n)) @ q.T
    b = rng.standard_normal(n)
    return a, b, np.linalg.solve(a, b)


def _rosenbrock(w):
    return (1 - w[0]) ** 2 + 100 * (w[1] - w[0] ** 2) ** 2


def _rosenbrock_grad(w):
    return np.array(
        [
            -2 * (1 - w[0]) - 400 * w[0] * (w[1] - w[0] ** 2),
            200 * (w[1] - w[0] ** 2),
        ]
    )


def _autograd(fun):
    """numpy ``(E, grad E)`` through the torch function (same rounding as SCG)."""

    def value(w):
        return fun(torch.tensor(w, dtype=torch.float64)).item()

    def grad(w):
        wt = torch.tensor(w, dtype=torch.float64, requires_grad=True)
        fun(wt).backward()
        return wt.grad.numpy()

    return value, grad


def _one_minus_cos(w):  # negative curvature for |w| > pi / 2
    return (1 - torch.cos(w)).sum()


def _soft_abs(w):  # tiny curvature far out: the first quadratic model overshoots
    return torch.sqrt(1 + w**2).sum()


def _make(fun, w0, dtype=torch.float64, **kwargs):
    w = torch.tensor(w0, dtype=dtype, requires_grad=True)
    opt = SCG([w], **kwargs)

    def closure():
        opt.zero_grad()
        loss = fun(w)
        loss.backward()
        return loss

    return w, opt, closure


def _reference_scg(fun, grad, w, n_epochs, sigma=SIGMA_GT, lambd=LAMBDA_GT):
    """Line-by-line numpy transcription of the docs/method.md §8.6.2 pseudo-code."""
    w = np.array(w, dtype=float)
    n = w.size
    e, g = fun(w), grad(w)
    p, success, lam, lam_bar = -g, True, lambd, 0.0
    delta = None
    trajectory, forced = [], 0
    for epoch in range(n_epochs):
        pp = p @ p
        if success:
            sk = sigma / math.sqrt(pp)
            s = (grad(w + sk * p) - g) / sk
            delta = p @ s
        delta = delta + (lam - lam_bar) * pp
        if delta <= 0:
            forced += 1
            lam_bar = 2 * (lam - delta / pp)
            delta = -delta + lam * pp
            lam = lam_bar
        mu = -(p @ g)
        alpha = mu / delta
        e_new = fun(w + alpha * p)
        comp = 2 * delta * (e - e_new) / mu**2
        if comp >= 0:
            g_old = g
            w = w + alpha * p
            e, g = e_new, grad(w)
            lam_bar, success = 0.0, True
            if epoch % n == 0:
                p = -g
            else:
                p = -g + (g @ g - g @ g_old) / mu * p
            pp = p @ p
            if comp >= 0.75:
                lam = lam / 4
        else:
            lam_bar, success = lam, False
        if comp < 0.25 and pp != 0:
            lam = lam + delta * (1 - comp) / pp
        trajectory.append((w.copy(), lam, comp >= 0))
    return trajectory, forced


# ------------------------------------------------------------------------ tests
@pytest.mark.parametrize("n", range(5, 11))
def test_quadratic_is_solved_in_about_n_steps(n):
    a, b, sol = _quadratic(n, seed=n)
    at, bt = torch.from_numpy(a), torch.from_numpy(b)
    w, opt, closure = _make(lambda w: 0.5 * w @ at @ w - bt @ w, np.zeros(n))
    errors = []
    for _ in range(n + 1):
        opt.step(closure)
        errors.append(np.linalg.norm(w.detach().numpy() - sol) / np.linalg.norm(sol))
    # Observed: 1e-6 reached after n or n + 1 steps (CG up to the λ0 shift).
    assert errors[-1] < 1e-6
    assert opt.info["n_accepted"] == n + 1 and opt.info["n_rejected"] == 0
    # Further steps polish until E differences drown in rounding (Δ is noise).
    for _ in range(2 * n):
        opt.step(closure)
        assert opt.info["lambd"] >= 0
    assert_allclose(w.detach().numpy(), sol, rtol=0, atol=1e-8)
    assert opt.info["grad_norm"] < 1e-7
    assert opt.grad_norm == opt.info["grad_norm"]


def test_rosenbrock_converges_to_the_minimum():
    w, opt, closure = _make(_rosenbrock, ROSENBROCK_START)
    reached = None
    for k in range(300):
        opt.step(closure)
        assert opt.info["lambd"] >= 0
        if reached is None and np.all(np.abs(w.detach().numpy() - 1) < 1e-4):
            reached = k + 1
    assert reached is not None and reached <= 150  # observed: 97 steps
    assert_allclose(w.detach().numpy(), ROSENBROCK_MIN, atol=1e-10)
    assert opt.info["n_rejected"] > 0  # the valley forces rejections
    assert opt.info["converged"]  # further steps cannot move w in float64


@pytest.mark.parametrize("reevaluate", [True, False])
def test_iterates_follow_the_spec_pseudo_code(reevaluate):
    n_epochs = 60
    expected, _ = _reference_scg(*_autograd(_rosenbrock), ROSENBROCK_START, n_epochs)
    w, opt, closure = _make(_rosenbrock, ROSENBROCK_START, reevaluate=reevaluate)
    for w_ref, lam_ref, accepted in expected:
        opt.step(closure)
        assert opt.info["success"] == accepted
        # Same branches; 1-ulp differences (dot-product order) grow to ~1e-7
        # over 60 epochs in the curved valley.
        assert_allclose(w.detach().numpy(), w_ref, rtol=1e-6)
        assert_allclose(opt.info["lambd"], lam_ref, rtol=1e-6)
    # 3 closure calls per accepted step and 2 per rejected one with reevaluation;
    # MATLAB's 2 and 1 (+ the initial one) without.
    acc, rej = opt.info["n_accepted"], opt.info["n_rejected"]
    assert acc + rej == n_epochs and rej > 0
    expected_evals = 3 * acc + 2 * rej if reevaluate else 1 + 2 * acc + rej
    assert opt.info["n_evals"] == expected_evals


def test_negative_curvature_is_handled_and_lambda_stays_non_negative():
    expected, forced = _reference_scg(*_autograd(_one_minus_cos), [2.5, -2.0], 25)
    assert forced > 0  # δ <= 0 branch exercised
    w, opt, closure = _make(_one_minus_cos, [2.5, -2.0])
    for w_ref, _, accepted in expected:
        opt.step(closure)
        assert opt.info["success"] == accepted
        assert opt.info["lambd"] >= 0 and opt.info["lambd_bar"] >= 0
        assert opt.info["delta"] > 0
        assert_allclose(w.detach().numpy(), w_ref, rtol=1e-9, atol=1e-12)
    assert_allclose(w.detach().numpy(), [0.0, 0.0], atol=1e-8)


def test_rejected_steps_leave_weights_unchanged():
    w, opt, closure = _make(_soft_abs, [3.0, -2.5])
    n_rejected = 0
    for _ in range(60):
        before = w.detach().clone()
        loss_before = _soft_abs(before).item()
        opt.step(closure)
        assert opt.info["lambd"] >= 0
        if opt.info["n_rejected"] > n_rejected:
            n_rejected = opt.info["n_rejected"]
            assert torch.equal(w.detach(), before)
            assert opt.info["comparison"] < 0
            assert opt.info["loss"] == loss_before
            # the gradient left in .grad belongs to the restored weights
            assert_allclose(
                w.grad.numpy(), (before / torch.sqrt(1 + before**2)).numpy()
            )
        else:
            assert _soft_abs(w.detach()).item() <= loss_before
    assert n_rejected >= 2  # observed: the first two steps overshoot
    assert_allclose(w.detach().numpy(), [0.0, 0.0], atol=1e-8)


def test_float32_parameters_keep_their_dtype_and_converge():
    a, b, sol = _quadratic(6, seed=0)
    at, bt = torch.tensor(a, dtype=torch.float32), torch.tensor(b, dtype=torch.float32)
    w, opt, closure = _make(
        lambda w: 0.5 * w @ at @ w - bt @ w, np.zeros(6), dtype=torch.float32
    )
    storage = w.data_ptr()
    for _ in range(30):
        opt.step(closure)
    assert w.dtype == torch.float32 and w.data_ptr() == storage  # written in place
    assert_allclose(w.detach().numpy(), sol, rtol=1e-4, atol=1e-5)


def test_several_groups_form_one_vector():
    a, b, sol = _quadratic(6, seed=3)
    at, bt = torch.from_numpy(a), torch.from_numpy(b)
    w1 = torch.zeros(2, dtype=torch.float64, requires_grad=True)
    w2 = torch.zeros((2, 2), dtype=torch.float64, requires_grad=True)
    opt = SCG([{"params": [w1]}, {"params": [w2]}])

    def closure():
        opt.zero_grad()
        w = torch.cat([w1, w2.reshape(-1)])
        loss = 0.5 * w @ at @ w - bt @ w
        loss.backward()
        return loss

    for _ in range(7):
        opt.step(closure)
    got = np.concatenate([w1.detach().numpy(), w2.detach().numpy().ravel()])
    assert_allclose(got, sol, rtol=1e-6)


def test_zero_gradient_is_a_no_op():
    w, opt, closure = _make(_one_minus_cos, [0.0, 0.0])
    opt.step(closure)
    assert opt.info["converged"] and opt.info["grad_norm"] == 0.0
    assert torch.equal(w.detach(), torch.zeros(2, dtype=torch.float64))


def test_step_returns_the_loss_before_the_step():
    w, opt, closure = _make(_rosenbrock, ROSENBROCK_START)
    first = opt.step(closure)
    assert_allclose(first.item(), _rosenbrock(np.array(ROSENBROCK_START)))
    assert opt.info["loss"] < first.item()
    assert not first.requires_grad


def test_state_dict_round_trip_continues_identically():
    w, opt, closure = _make(_rosenbrock, ROSENBROCK_START)
    for _ in range(10):
        opt.step(closure)
    w2, opt2, closure2 = _make(_rosenbrock, w.detach().numpy())
    opt2.load_state_dict(opt.state_dict())
    for _ in range(10):
        opt.step(closure)
        opt2.step(closure2)
    assert_allclose(w2.detach().numpy(), w.detach().numpy(), rtol=1e-12)


def test_external_weight_change_restarts_the_direction():
    w, opt, closure = _make(_rosenbrock, ROSENBROCK_START, reevaluate=False)
    for _ in range(5):
        opt.step(closure)
    with torch.no_grad():
        w.copy_(torch.tensor([0.5, 0.5], dtype=torch.float64))
    lam = opt.info["lambd"]
    n_evals = opt.info["n_evals"]
    opt.step(closure)
    # As a fresh start from (0.5, 0.5) with the current λ: p = -g, new curvature.
    trajectory, _ = _reference_scg(*_autograd(_rosenbrock), [0.5, 0.5], 1, lambd=lam)
    w_ref, _, accepted = trajectory[0]
    assert accepted and opt.info["success"]
    assert_allclose(w.detach().numpy(), w_ref, rtol=1e-12)
    assert opt.info["n_evals"] == n_evals + 3  # re-evaluated at the moved weights


def test_step_without_closure_raises():
    w, opt, _ = _make(_rosenbrock, ROSENBROCK_START)
    with pytest.raises(ValueError, match="requires a closure"):
        opt.step()


def test_closure_returning_none_raises_and_restores_weights():
    w, opt, closure = _make(_rosenbrock, ROSENBROCK_START)
    opt.step(closure)
    before = w.detach().clone()
    calls = []

    def bad_closure():
        calls.append(1)
        if len(calls) == 1:
            return closure()
        return None

    with pytest.raises(ValueError, match="must return the loss"):
        opt.step(bad_closure)
    assert torch.equal(w.detach(), before)


@pytest.mark.parametrize(
    ("kwargs", "match"), [({"sigma": 0.0}, "sigma"), ({"lambd": -1.0}, "lambd")]
)
def test_invalid_hyperparameters_raise(kwargs, match):
    with pytest.raises(ValueError, match=match):
        SCG([torch.zeros(2, requires_grad=True)], **kwargs)


def test_groups_with_different_settings_raise():
    groups = [
        {"params": [torch.zeros(1, requires_grad=True)]},
        {"params": [torch.zeros(1, requires_grad=True)], "sigma": 1e-3},
    ]
    with pytest.raises(ValueError, match="same in every group"):
        SCG(groups)


def test_defaults_are_matlab_trainscg():
    opt = SCG([torch.zeros(1, requires_grad=True)])
    assert opt.defaults["sigma"] == SIGMA_GT and opt.defaults["lambd"] == LAMBDA_GT
    assert opt.grad_norm is None  # no step taken yet


def test_skorch_binary_classifier_trains_with_scg():
    skorch = pytest.importorskip("skorch")
    rng = np.random.default_rng(0)
    x = np.vstack([rng.normal(-1, 0.7, (50, 2)), rng.normal(1, 0.7, (50, 2))])
    y = np.repeat([0, 1], 50)

    class _Mlp(torch.nn.Module):
        def __init__(self, hidden=5):
            super().__init__()
            self.body = torch.nn.Sequential(
                torch.nn.Linear(2, hidden), torch.nn.Tanh(), torch.nn.Linear(hidden, 1)
            )

        def forward(self, x):
            return self.body(x).squeeze(-1)

    net = skorch.NeuralNetBinaryClassifier(
        _Mlp,
        optimizer=SCG,
        batch_size=-1,  # full batch, as MATLAB trainscg
        max_epochs=60,
        train_split=None,
        verbose=0,
    )
    net.fit(x.astype(np.float32), y.astype(np.float32))
    accuracy = np.mean(net.predict(x.astype(np.float32)) == y)
    assert accuracy > 0.95
    info = net.optimizer_.info
    assert info["n_iter"] == 60 and info["n_accepted"] > 40
    losses = net.history[:, "train_loss"]
    assert losses[-1] < 0.1 * losses[0]

"""Scaled Conjugate Gradient as MATLAB ``trainscg`` (Møller 1993), a torch optimiser."""

# SPDX-License-Identifier: BSD-3-Clause

import math
from numbers import Real

import torch
from torch.optim import Optimizer

__all__ = ["SCG"]

SCG_SIGMA = 5.0e-5  # docs/method.md §8.6.1: finite-difference step of trainscg
SCG_LAMBDA = 5.0e-7  # docs/method.md §8.6.1: initial scale parameter of trainscg
GOOD_REDUCTION = 0.75  # docs/method.md §8.6.2: Δ >= 0.75 -> λ shrinks
LAMBDA_SHRINK = 0.25  # docs/method.md §8.6.2: λ <- λ / 4
POOR_REDUCTION = 0.25  # docs/method.md §8.6.2: Δ < 0.25 -> λ grows

_INFO_KEYS = (
    "n_iter",
    "n_accepted",
    "n_rejected",
    "n_evals",
    "loss",
    "grad_norm",
    "lambd",
    "lambd_bar",
    "delta",
    "comparison",
    "success",
    "converged",
)


def _work_dtype(device):
    # Scalars and vectors of the method are kept in float64 (MATLAB's double);
    # MPS has no float64.
    return torch.float32 if device.type == "mps" else torch.float64


class SCG(Optimizer):
    """Scaled Conjugate Gradient optimiser, iteration for iteration MATLAB ``trainscg``.

    Møller's scaled conjugate gradient: a conjugate-gradient direction, a
    step size from a finite-difference Hessian-vector product regularised by a
    Levenberg-Marquardt-like scale ``λ``, and no line search. All parameters
    of all parameter groups form one flat weight vector ``w``. One call of
    :meth:`step` is one SCG iteration (one MATLAB epoch); a rejected step
    consumes a call and leaves the parameters unchanged.

    Parameters
    ----------
    params : iterable of torch.Tensor or dict
        Parameters to optimise, or parameter groups (all merged into one
        vector; ``sigma``, ``lambd`` and ``reevaluate`` must agree across
        groups).
    lr : float, default=1.0
        Unused: SCG has no learning rate. Accepted because skorch passes
        ``lr`` to every optimiser.
    sigma : float, default=5e-5
        ``σ``; the Hessian-vector product uses the gradient at
        ``w + (σ / ‖p‖) p``.
    lambd : float, default=5e-7
        Initial scale parameter ``λ0`` (>= 0).
    reevaluate : bool, default=True
        If True every step starts by calling the closure at the current
        weights (3 evaluations per accepted iteration, 2 per rejected one).
        This keeps the method correct when the batch changes between steps
        or the weights are changed outside the optimiser, and makes the
        first closure call of a step (the loss skorch records) return
        ``E(w)``. If False the loss and gradient computed at the accepted
        point of the previous step are reused (MATLAB's 2 and 1
        evaluations, same iterates in full-batch training); use it only with
        full-batch training, and note that the first closure call of a step
        is then at ``w + σk p`` or at a trial point, so the loss skorch
        records is not exactly ``E(w)``.

    Attributes
    ----------
    grad_norm : float or None
        ``‖∇E‖`` at the current weights after the last step, for MATLAB's
        ``min_grad`` stopping rule (same as ``info["grad_norm"]``).
    info : dict
        Read-only view of the scalar state after the last step: ``n_iter``
        (steps taken), ``n_accepted``, ``n_rejected``, ``n_evals`` (closure
        calls), ``loss`` and ``grad_norm`` (``E`` and ``‖∇E‖`` at the current
        weights, for the ``min_grad`` stopping rule), ``lambd``, ``lambd_bar``,
        ``delta``, ``comparison`` (``Δ`` of the last trial), ``success`` and
        ``converged`` (the gradient is exactly zero, or the accepted step
        could not change the weights in floating point). The same entries, plus
        the vectors ``weights``, ``grad`` and ``direction``, are stored in
        ``state[first_parameter]`` as LBFGS does, so they follow
        ``state_dict``.

    See Also
    --------
    torch.optim.LBFGS : The other closure-driven full-batch optimiser.

    Notes
    -----
    Implements the pseudo-code of docs/method.md §8.6.2 (MATLAB ``trainscg``,
    σ and λ defaults of §8.6.1), with ``g = ∇E(w)``, ``p`` the direction:
    ``s = (∇E(w + σk p) - g) / σk`` with ``σk = σ / ‖p‖`` (only after a
    success), ``δ = pᵀs + (λ - λ̄)‖p‖²`` (made positive if needed),
    ``μ = -pᵀg``, ``α = μ / δ``, comparison ``Δ = 2δ(E(w) - E(w + αp)) / μ²``;
    accept when ``Δ >= 0``; the direction restarts at ``-g`` when the
    0-based iteration counter is a multiple of the number of weights, else
    ``p <- -g + β p`` with ``β = (gᵀg - gᵀg_old) / μ``. Stopping rules,
    validation and best-weight tracking belong to the trainer.

    The closure must zero the gradients, compute the loss, call ``backward``
    and return the loss, as for :class:`torch.optim.LBFGS` (skorch's
    ``train_step`` passes such a closure). Parameters are written in place
    (``copy_``), never rebound, so views such as ``nn.LSTM``'s flat weights
    stay valid and dtypes never change.

    Behaviour where MATLAB would break down (documented deviations): a zero
    gradient makes the step a no-op (``converged``); a direction with
    ``‖p‖ = 0`` or ``μ = 0`` while ``g ≠ 0`` restarts at ``p = -g`` (MATLAB
    would stall on NaN); a non-finite trial loss or gradient is a rejection
    with ``λ`` raised as for ``Δ = 0``; an accepted step that cannot change
    the weights in floating point (``w + αp == w``) sets ``converged`` and
    does not raise ``λ`` (MATLAB would grow ``λ`` until it overflows; its
    ``min_grad`` rule normally stops training long before); weights changed
    outside the optimiser restart the direction at ``p = -g``.

    References
    ----------
    .. [1] M. F. Møller, "A scaled conjugate gradient algorithm for fast
       supervised learning", Neural Networks 6(4), 525-533, 1993.

    Examples
    --------
    >>> import torch
    >>> from skgesture.utils._scg import SCG
    >>> A = torch.tensor([[3.0, 1.0], [1.0, 2.0]], dtype=torch.float64)
    >>> b = torch.tensor([1.0, 1.0], dtype=torch.float64)
    >>> w = torch.zeros(2, dtype=torch.float64, requires_grad=True)
    >>> opt = SCG([w])
    >>> def closure():
    ...     opt.zero_grad()
    ...     loss = 0.5 * w @ A @ w - b @ w
    ...     loss.backward()
    ...     return loss
    >>> for _ in range(3):
    ...     _ = opt.step(closure)
    >>> w.detach().numpy().round(6).tolist()  # A^-1 b
    [0.2, 0.4]
    >>> opt.info["n_accepted"], opt.info["grad_norm"] < 1e-6
    (3, True)
    """

    def __init__(
        self, params, lr=1.0, *, sigma=SCG_SIGMA, lambd=SCG_LAMBDA, reevaluate=True
    ):
        if not isinstance(sigma, Real) or not sigma > 0 or not math.isfinite(sigma):
            raise ValueError(f"sigma must be a positive number, got {sigma!r}.")
        if not isinstance(lambd, Real) or not lambd >= 0 or not math.isfinite(lambd):
            raise ValueError(f"lambd must be a number >= 0, got {lambd!r}.")
        defaults = {
            "lr": lr,
            "sigma": float(sigma),
            "lambd": float(lambd),
            "reevaluate": bool(reevaluate),
        }
        super().__init__(params, defaults)
        first = self.param_groups[0]
        for group in self.param_groups[1:]:
            for key in ("sigma", "lambd", "reevaluate"):
                if group[key] != first[key]:
                    raise ValueError(
                        f"SCG treats all parameters as one vector: {key!r} must be "
                        f"the same in every group, got {first[key]!r} and "
                        f"{group[key]!r}."
                    )

    # ------------------------------------------------------------------ helpers
    def _all_params(self):
        return [p for group in self.param_groups for p in group["params"]]

    @property
    def info(self):
        """Scalar SCG state after the last step (see the class docstring)."""
        params = self._all_params()
        state = self.state[params[0]] if params else {}
        return {key: state.get(key) for key in _INFO_KEYS}

    @property
    def grad_norm(self):
        """``‖∇E‖`` at the current weights after the last step (None before)."""
        return self.info["grad_norm"]

    @staticmethod
    def _gather(params, dtype, device):
        return torch.cat(
            [p.detach().reshape(-1).to(device=device, dtype=dtype) for p in params]
        )

    @staticmethod
    def _gather_grad(params, dtype, device):
        flats = []
        for p in params:
            if p.grad is None:
                flats.append(torch.zeros(p.numel(), dtype=dtype, device=device))
            else:
                grad = p.grad.to_dense() if p.grad.is_sparse else p.grad
                flats.append(grad.reshape(-1).to(device=device, dtype=dtype))
        return torch.cat(flats)

    @staticmethod
    def _scatter_(tensors, vec):
        # In-place copy (casts dtype/device); unlike vector_to_parameters it
        # never rebinds ``.data``.
        offset = 0
        for t in tensors:
            n = t.numel()
            t.copy_(vec[offset : offset + n].view(t.shape))
            offset += n

    @staticmethod
    def _restore_grad_(params, grad):
        offset = 0
        for p in params:
            n = p.numel()
            if p.grad is not None:
                p.grad.copy_(grad[offset : offset + n].view(p.shape))
            offset += n

    def _evaluate(self, closure, params, dtype, device, state):
        self.zero_grad(set_to_none=True)
        with torch.enable_grad():
            loss = closure()
        if loss is None:
            raise ValueError("The SCG closure must return the loss, got None.")
        state["n_evals"] += 1
        loss = torch.as_tensor(loss).detach()
        return loss, float(loss), self._gather_grad(params, dtype, device)

    # --------------------------------------------------------------------- step
    @torch.no_grad()
    def step(self, closure=None):
        """Perform one SCG iteration (one MATLAB ``trainscg`` epoch).

        Parameters
        ----------
        closure : callable
            Re-evaluates the model: zeroes the gradients, computes the loss,
            calls ``backward`` and returns the loss. Required; it is called
            1 to 3 times per step.

        Returns
        -------
        loss : torch.Tensor
            The loss at the weights the step started from (detached).
        """
        if closure is None:
            raise ValueError(
                "SCG.step requires a closure that zeroes the gradients, computes "
                "the loss, calls loss.backward() and returns the loss (as for "
                "torch.optim.LBFGS)."
            )
        params = self._all_params()
        if not params:
            return None
        group = self.param_groups[0]
        sigma, reevaluate = group["sigma"], group["reevaluate"]
        device = params[0].device
        dtype = _work_dtype(device)
        state = self.state[params[0]]

        w = self._gather(params, dtype, device)
        n_weights = w.numel()
        fresh = "direction" not in state or state["direction"].numel() != n_weights
        moved = not fresh and not torch.equal(w, state["weights"].to(w))
        if fresh:
            state.update(
                n_iter=0,
                n_accepted=0,
                n_rejected=0,
                n_evals=0,
                lambd=group["lambd"],
                lambd_bar=0.0,
                delta=math.nan,
                comparison=math.nan,
                success=True,
                converged=False,
            )

        first_loss = None
        if fresh or moved or reevaluate:
            first_loss, loss, g = self._evaluate(closure, params, dtype, device, state)
        else:
            loss, g = state["loss"], state["grad"].to(w)
        if first_loss is None:
            first_loss = torch.tensor(loss)

        lam, lam_bar = state["lambd"], state["lambd_bar"]
        success, delta = state["success"], state["delta"]
        if fresh or moved:
            p, success, lam_bar = -g, True, 0.0
        else:
            p = state["direction"].to(w)

        epoch = state["n_iter"]
        state["n_iter"] = epoch + 1
        g_sq = float(g @ g)

        def _store(**values):
            state.update(values)
            state["weights"], state["grad"], state["direction"] = w, g, p

        if g_sq == 0.0:  # stationary point: nothing to do
            _store(loss=loss, grad_norm=0.0, converged=True)
            return first_loss

        p_sq = float(p @ p)
        mu = -float(p @ g)
        if p_sq == 0.0 or mu == 0.0 or not (math.isfinite(p_sq) and math.isfinite(mu)):
            p, p_sq, mu, success, lam_bar = -g, g_sq, g_sq, True, 0.0

        try:
            if success:  # second-order information along p
                sigma_k = sigma / math.sqrt(p_sq)
                self._scatter_(params, w + sigma_k * p)
                _, _, g_sigma = self._evaluate(closure, params, dtype, device, state)
                delta = float(p @ ((g_sigma - g) / sigma_k))
            delta = delta + (lam - lam_bar) * p_sq
            if delta <= 0.0:  # make the scaled Hessian positive definite
                lam_bar = 2.0 * (lam - delta / p_sq)
                delta = -delta + lam * p_sq
                lam = lam_bar
            alpha = mu / delta
            self._scatter_(params, w + alpha * p)
            _, loss_new, g_new = self._evaluate(closure, params, dtype, device, state)
        except BaseException:
            self._scatter_(params, w)
            raise

        finite = math.isfinite(loss_new) and bool(torch.isfinite(g_new).all())
        comparison = (
            2.0 * delta * (loss - loss_new) / (mu * mu) if finite else -math.inf
        )
        if comparison >= 0.0:  # accept
            g_old, g = g, g_new
            loss, lam_bar, success = loss_new, 0.0, True
            if epoch % n_weights == 0:
                p = -g
            else:
                beta = (float(g @ g) - float(g @ g_old)) / mu
                p = -g + beta * p
            p_sq = float(p @ p)
            if comparison >= GOOD_REDUCTION:
                lam = LAMBDA_SHRINK * lam
            w_new = self._gather(params, dtype, device)
            stalled = torch.equal(w_new, w)
            w = w_new
            state["n_accepted"] += 1
        else:  # reject: restore the weights and their gradient
            self._scatter_(params, w)
            self._restore_grad_(params, g)
            lam_bar, success, stalled = lam, False, False
            state["n_rejected"] += 1
        if comparison < POOR_REDUCTION and p_sq != 0.0 and not stalled:
            grow = comparison if finite else 0.0
            lam = lam + delta * (1.0 - grow) / p_sq

        _store(
            loss=loss,
            grad_norm=math.sqrt(float(g @ g)),
            lambd=lam,
            lambd_bar=lam_bar,
            delta=delta,
            comparison=comparison,
            success=success,
            converged=stalled,
        )
        return first_loss

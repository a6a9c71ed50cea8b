"""The one optimisation loop of the neural fits: Adam over stages of step functions.

Each fit (:func:`neural.flow.fit_flow_surface`, :func:`neural.crease_refit.crease_refine`)
seeds its random streams with :func:`seeded`, checks its device with
:func:`torch_device`, and hands :func:`train` a list of :class:`Stage` objects whose
step functions build one loss each. The loop owns what is common: the Adam optimiser
(shared by all stages of one call), the optional cosine learning-rate decay and
gradient clipping, the progress bar, per-stage step counts and timings, the
best-so-far state, and Ctrl-C (``KeyboardInterrupt``, or a ``stop`` event set from
another thread), which ends the loop early and is reported, not raised.

The optimiser sees the same operations in the same order as a hand-written loop
(zero the gradients, build the loss, backward, clip, step, schedule), so seeded CPU
runs are reproducible bit for bit.
"""

from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

__all__ = ["Step", "Stage", "Training", "train", "seeded", "torch_device", "GLOBAL_STREAM"]


@dataclass
class Step:
    """What a step function returns.

    Attributes
    ----------
    loss : scalar torch tensor
        The loss to minimise; the loop calls ``loss.backward()``.
    log : dict of str -> float
        Values shown on the progress bar (NaN values are left out of it).
    state : object, optional
        What the fit would return if it stopped after this step (e.g. the integrated
        field). Once the optimiser has stepped, the loop keeps it as the best state so
        far if the ``keep`` predicate of :func:`train` accepts it.
    after : callable, optional
        Called with no argument once the optimiser has stepped (e.g. to read
        gradients of intermediate tensors for the next step).
    """

    loss: Any
    log: dict = field(default_factory=dict)
    state: Any = None
    after: Callable[[], None] | None = None


@dataclass
class Stage:
    """A named run of ``steps`` calls ``step(k)``, ``k = 0 .. steps - 1``.

    ``start`` (optional) runs when the stage begins, inside the interruptible part of
    the loop; a non-None return value is offered as a state like :attr:`Step.state`.
    """

    name: str
    steps: int
    step: Callable[[int], Step]
    start: Callable[[], Any] | None = None


@dataclass
class Training:
    """Outcome of :func:`train`.

    Attributes
    ----------
    best : object or None
        The last state offered by a completed step (or stage start) that ``keep``
        accepted; None if there was none.
    interrupted : bool
        True when Ctrl-C ended the loop.
    steps : dict of str -> int
        Completed steps per stage.
    timings : dict of str -> float
        Seconds per stage that ran to its end (0.0 for the others).
    log : dict of str -> float
        The log of the last completed step (empty if none completed).
    """

    best: Any
    interrupted: bool
    steps: dict
    timings: dict
    log: dict


#: Held while a fit seeds torch's global stream and draws its network's first weights from
#: it (:func:`seeded`, then the network's constructor): fits run side by side in threads
#: (:func:`neural.parts.fit_parts`) then draw the weights each would draw alone.
GLOBAL_STREAM = threading.Lock()


def seeded(seed: int, device="cpu"):
    """Seed torch's global stream and return ``(generator, rng)`` for ``seed``.

    Parameters
    ----------
    seed : int
    device : str or torch.device
        Device of the returned ``torch.Generator``.

    Returns
    -------
    gen : torch.Generator seeded with ``seed`` (network-independent sampling)
    rng : numpy.random.Generator, ``default_rng(seed)`` (host-side sampling)
    """
    import torch

    torch.manual_seed(seed)
    gen = torch.Generator(device=device)
    gen.manual_seed(seed)
    return gen, np.random.default_rng(seed)


def torch_device(device):
    """``device`` as a ``torch.device`` that exists here (CPU or an available CUDA device).

    Raises
    ------
    ValueError
        Neither ``"cpu"`` nor ``"cuda"`` (``"cuda:1"``...), or CUDA requested but absent.
    """
    import torch

    try:
        dev = torch.device(device)
    except (RuntimeError, TypeError) as exc:
        raise ValueError(f"device must be 'cpu' or 'cuda', got {device!r}") from exc
    if dev.type not in ("cpu", "cuda"):
        raise ValueError(f"device must be 'cpu' or 'cuda', got {device!r}")
    if dev.type == "cuda" and not torch.cuda.is_available():
        raise ValueError(f"device {device!r} requested but CUDA is not available")
    return dev


def _is_finite(state) -> bool:
    import torch

    return bool(torch.isfinite(state).all()) if isinstance(state, torch.Tensor) else True


def train(params, stages, *, lr: float, grad_clip: float = 0.0, schedule: str = "constant",
          lr_min: float = 0.0, progress: bool = False, desc: str = "fit",
          keep: Callable[[Any], bool] = _is_finite,
          stop: threading.Event | None = None) -> Training:
    """Minimise the step functions' losses with one Adam optimiser, stage after stage.

    Parameters
    ----------
    params : iterable of torch parameters
    stages : sequence of Stage
        Run in order; the optimiser state carries over from one stage to the next.
    lr : float
        Adam learning rate.
    grad_clip : float
        Clip the gradient norm to this value before each step (0 = off).
    schedule : {"constant", "cosine"}
        ``"cosine"`` anneals the learning rate from ``lr`` to ``lr_min`` over all steps
        of all stages (``torch.optim.lr_scheduler.CosineAnnealingLR``).
    lr_min : float
        Final learning rate of the cosine schedule.
    progress : bool
        Show a bar over all steps with the stage and the step's log
        (:func:`curvenet.core.progress.progress_bar`: tqdm on a terminal, plain lines
        elsewhere).
    desc : str
        Label of the bar.
    keep : callable
        Predicate on offered states (default: a tensor state must be finite everywhere).
    stop : threading.Event, optional
        Set from another thread, the run stops before its next step as at Ctrl-C
        (``interrupted``); a fit in a worker thread gets no KeyboardInterrupt.

    Returns
    -------
    Training

    Examples
    --------
    >>> import torch
    >>> x = torch.nn.Parameter(torch.tensor([3.0]))
    >>> quadratic = lambda k: Step((x ** 2).sum(), state=x.detach().clone())
    >>> out = train([x], [Stage("fit", 200, quadratic)], lr=0.1)
    >>> bool(out.best.abs() < 0.1), out.interrupted
    (True, False)
    """
    import torch

    if schedule not in ("constant", "cosine"):
        raise ValueError(f"schedule must be 'constant' or 'cosine', got {schedule!r}")
    params = list(params)
    total = sum(s.steps for s in stages)
    opt = _Adam(params, lr, cosine=(total, lr_min) if schedule == "cosine" else None)
    out = Training(None, False, {s.name: 0 for s in stages}, {s.name: 0.0 for s in stages}, {})
    bar = None
    if progress:
        from curvenet.core.progress import progress_bar
        bar = progress_bar(total, desc=desc, unit="step")
    try:
        for stage in stages:
            t0 = time.perf_counter()
            if stage.start is not None:
                _offer(out, stage.start(), keep)
            for k in range(stage.steps):
                if stop is not None and stop.is_set():
                    out.interrupted = True
                    return out
                opt.zero_grad()
                step = stage.step(k)
                step.loss.backward()
                if grad_clip > 0:
                    torch.nn.utils.clip_grad_norm_(params, grad_clip)
                opt.step()
                if step.after is not None:
                    step.after()
                _offer(out, step.state, keep)
                out.log = step.log
                out.steps[stage.name] += 1
                if bar is not None:
                    bar.update(1)
                    bar.set_postfix({"stage": stage.name, **{t: f"{v:.3g}" for t, v in
                                                             step.log.items() if v == v}},
                                    refresh=False)
            out.timings[stage.name] = time.perf_counter() - t0
    except KeyboardInterrupt:
        out.interrupted = True
    finally:
        if bar is not None:
            bar.close()
    return out


class _Adam:
    """Adam with torch's defaults, and optionally the cosine decay of its learning rate.

    The same values bit for bit as ``torch.optim.Adam`` (its single-tensor path, which
    it takes on the CPU) followed by ``torch.optim.lr_scheduler.CosineAnnealingLR``'s
    step (its recursive form): ``tests/neural/test_training.py`` runs both. Written out
    because constructing a ``torch.optim`` optimiser imports TorchDynamo, about a second
    of each process that fits, for a compiler these fits never use.

    Parameters
    ----------
    params : list of torch parameters
    lr : float
    cosine : (int, float) or None
        ``(total, lr_min)``: the rate falls from ``lr`` to ``lr_min`` over ``total`` steps
        (no more are taken).
    """

    BETAS, EPS = (0.9, 0.999), 1e-8

    def __init__(self, params, lr: float, cosine=None):
        self.params, self.lr, self.cosine = params, lr, cosine
        self.t = 0                                  # steps taken
        self.moments: dict = {}

    def zero_grad(self) -> None:
        for p in self.params:
            p.grad = None

    def step(self) -> None:
        import torch

        b1, b2 = self.BETAS
        self.t += 1
        with torch.no_grad():
            for p in self.params:
                if p.grad is None:
                    continue
                if p not in self.moments:       # [first moment, second, own steps]
                    self.moments[p] = [torch.zeros_like(p), torch.zeros_like(p), 0]
                state = self.moments[p]
                state[2] += 1
                m, v, n = state
                m.lerp_(p.grad, 1 - b1)
                v.mul_(b2).addcmul_(p.grad, p.grad, value=1 - b2)
                denom = (v.sqrt() / (1 - b2 ** n) ** 0.5).add_(self.EPS)
                p.addcdiv_(m, denom, value=-(self.lr / (1 - b1 ** n)))
        if self.cosine is not None:             # torch's recursive form, for t <= total
            total, lr_min = self.cosine
            self.lr = ((1 + math.cos(math.pi * self.t / total))
                       / (1 + math.cos(math.pi * (self.t - 1) / total))
                       * (self.lr - lr_min) + lr_min)


def _offer(out: Training, state, keep) -> None:
    if state is not None and keep(state):
        out.best = state

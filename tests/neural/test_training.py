"""The shared optimisation loop of the neural fits (neural.training)."""

import numpy as np
import pytest
import torch

from curvenet.neural.training import Stage, Step, seeded, torch_device, train

TARGET = torch.tensor([1.0, -2.0, 0.5])


def _quadratic(x, fail_at=None, nan_from=None):
    """Step function of |x - TARGET|^2 offering x as the state; raises / poisons on request."""

    def step(k):
        if k == fail_at:
            raise KeyboardInterrupt
        state = x.detach().clone()
        if nan_from is not None and k >= nan_from:
            state = state * float("nan")
        loss = ((x - TARGET) ** 2).sum()
        return Step(loss, {"loss": float(loss.detach())}, state=state)

    return step


def _hand_written_adam(x0, steps, lr):
    """The reference: plain Adam on the same quadratic, states after every step."""
    x = torch.nn.Parameter(x0.clone())
    opt = torch.optim.Adam([x], lr=lr)
    states = []
    for _ in range(steps):
        opt.zero_grad()
        ((x - TARGET) ** 2).sum().backward()
        opt.step()
        states.append(x.detach().clone())
    return states


def test_minimises_a_quadratic_like_hand_written_adam():
    x = torch.nn.Parameter(torch.zeros(3))
    out = train([x], [Stage("fit", 300, _quadratic(x))], lr=0.05)
    assert not out.interrupted and out.steps == {"fit": 300}
    assert torch.allclose(x.detach(), TARGET, atol=1e-3)
    # the offered state is taken before the step: the best is the state of the last step
    ref = _hand_written_adam(torch.zeros(3), 300, 0.05)
    assert torch.equal(out.best, ref[-2]) and torch.equal(x.detach(), ref[-1])
    assert out.log["loss"] < 1e-5


def test_keyboard_interrupt_returns_best_so_far():
    x = torch.nn.Parameter(torch.zeros(3))
    out = train([x], [Stage("a", 5, _quadratic(x)), Stage("b", 10, _quadratic(x, fail_at=4))],
                lr=0.05)
    assert out.interrupted
    assert out.steps == {"a": 5, "b": 4}
    assert out.timings["a"] > 0 and out.timings["b"] == 0.0   # "b" did not run to its end
    # 9 completed steps; the last offered state is x after 8 steps
    assert torch.equal(out.best, _hand_written_adam(torch.zeros(3), 8, 0.05)[-1])


def test_a_stop_event_set_elsewhere_ends_the_run_like_ctrl_c():
    import threading
    stop = threading.Event()
    x = torch.nn.Parameter(torch.zeros(3))
    quadratic = _quadratic(x)

    def step(k):                        # another thread would set it; here step 3 does
        if k == 3:
            stop.set()
        return quadratic(k)

    out = train([x], [Stage("a", 10, step), Stage("b", 10, quadratic)], lr=0.05, stop=stop)
    assert out.interrupted and out.steps == {"a": 4, "b": 0}
    assert torch.equal(out.best, _hand_written_adam(torch.zeros(3), 3, 0.05)[-1])


def test_non_finite_states_are_not_kept():
    x = torch.nn.Parameter(torch.zeros(3))
    out = train([x], [Stage("fit", 10, _quadratic(x, nan_from=6))], lr=0.05)
    assert torch.isfinite(out.best).all()
    assert torch.equal(out.best, _hand_written_adam(torch.zeros(3), 5, 0.05)[-1])


def test_stage_start_offers_a_state_and_after_runs_after_the_step():
    x = torch.nn.Parameter(torch.zeros(1))
    seen = []

    def step(k):
        return Step((x - 1.0).pow(2).sum(), after=lambda: seen.append(float(x.detach())))

    out = train([x], [Stage("s", 0, step, start=lambda: torch.tensor([7.0])),
                      Stage("t", 3, step)], lr=0.1)
    assert float(out.best) == 7.0
    assert len(seen) == 3 and seen[0] > 0      # x had already moved when `after` ran


def test_cosine_schedule_and_clipping_match_torch():
    def run(opt_fn, **kw):
        torch.manual_seed(0)
        x = torch.nn.Parameter(torch.randn(4) * 10)
        if opt_fn is None:
            train([x], [Stage("s", 20, lambda k: Step(((x - 1) ** 4).sum()))], lr=0.3, **kw)
        else:
            opt_fn(x)
        return x.detach()

    def reference(x):
        opt = torch.optim.Adam([x], lr=0.3)
        sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, 20, eta_min=0.01)
        for _ in range(20):
            opt.zero_grad()
            ((x - 1) ** 4).sum().backward()
            torch.nn.utils.clip_grad_norm_([x], 2.0)
            opt.step()
            sched.step()

    assert torch.equal(run(None, schedule="cosine", lr_min=0.01, grad_clip=2.0), run(reference))
    with pytest.raises(ValueError, match="schedule"):
        train([], [], lr=0.1, schedule="step")


def test_progress_bar_runs_and_other_errors_propagate(capsys):
    x = torch.nn.Parameter(torch.zeros(1))

    def bad(k):
        raise FloatingPointError("boom")

    out = train([x], [Stage("s", 3, lambda k: Step(x.pow(2).sum(), {"v": float("nan"),
                                                                      "w": 2.0}))],
                lr=0.1, progress=True, desc="quad")
    assert out.steps == {"s": 3}
    err = capsys.readouterr().err        # not a terminal: plain lines
    assert "quad: 3/3 step (stage=s, w=2)" in err and "refresh" not in err and "v=" not in err
    with pytest.raises(FloatingPointError):
        train([x], [Stage("s", 3, bad)], lr=0.1, progress=True)


def test_seeded_streams_are_reproducible():
    g1, r1 = seeded(5)
    a = (torch.rand(3, generator=g1), r1.random(3), torch.rand(2))
    g2, r2 = seeded(5)
    b = (torch.rand(3, generator=g2), r2.random(3), torch.rand(2))
    assert torch.equal(a[0], b[0]) and np.array_equal(a[1], b[1]) and torch.equal(a[2], b[2])


@pytest.mark.parametrize("device", ["tpu", 3.5, "cuda:0" if not torch.cuda.is_available()
                                    else "meta"])
def test_torch_device_rejects_what_is_not_here(device):
    with pytest.raises(ValueError, match="device"):
        torch_device(device)
    assert torch_device("cpu").type == "cpu"


@pytest.mark.parametrize("schedule", ["constant", "cosine"])
def test_a_network_trains_as_torch_optim_would_bit_for_bit(schedule):
    """The loop's own Adam against ``torch.optim.Adam`` (and ``CosineAnnealingLR``) on a
    small MLP with several parameter tensors, one of which has no gradient on odd steps."""
    def fit(reference):
        torch.manual_seed(5)
        net = torch.nn.Sequential(torch.nn.Linear(3, 16), torch.nn.Tanh(), torch.nn.Linear(16, 1))
        extra = torch.nn.Parameter(torch.randn(4))
        params = [*net.parameters(), extra]
        x = torch.randn(64, 3)

        def loss(k):
            value = (net(x) - x[:, :1] ** 2).pow(2).mean()
            return value + (extra.pow(2).sum() if k % 2 == 0 else 0.0)

        kw = {"schedule": "cosine", "lr_min": 1e-4} if schedule == "cosine" else {}
        if reference:
            opt = torch.optim.Adam(params, lr=0.01)
            sched = (torch.optim.lr_scheduler.CosineAnnealingLR(opt, 40, eta_min=1e-4)
                     if kw else None)
            for k in range(40):
                opt.zero_grad(set_to_none=True)
                loss(k).backward()
                torch.nn.utils.clip_grad_norm_(params, 0.5)
                opt.step()
                if sched is not None:
                    sched.step()
        else:
            train(params, [Stage("a", 15, lambda k: Step(loss(k))),
                           Stage("b", 25, lambda k: Step(loss(k + 15)))],
                  lr=0.01, grad_clip=0.5, **kw)
        return [p.detach().clone() for p in params]

    assert all(torch.equal(a, b) for a, b in zip(fit(False), fit(True)))

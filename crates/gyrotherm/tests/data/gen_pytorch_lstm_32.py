#!/usr/bin/env python3
"""Writes pytorch_lstm_5x32.json: a PyTorch reference for a 32-unit LSTM, float64.

Made like reference/lstm/pytorch_lstm_2x8.json (same keys for params, cases, gradients), with
a minibatch part for the batched truncated-BPTT path:

- params: nn.LSTM(5, 32, batch_first=True) + nn.Linear(32, 1), every value k/64 with k an
  integer in [-11, 11] (about PyTorch's U(-1/sqrt(32), 1/sqrt(32)) range; exact in binary and
  short in decimal, which keeps the file small).
- cases: outputs and final states (y, h_n, c_n) for a zero and a non-zero start state and a
  longer smooth run; the MSE loss for the first case.
- minibatch: windows of `window` steps cut from one series at the listed starts, `batch`
  windows per Adam step, zero start state, the first `burn_in` steps of each window left out
  of the loss (MSE over the counted steps of all windows of the batch). Step 0's gradient of
  every parameter is stored (the one gradient in the file: a 32-unit network has 5025
  parameters, and each full set costs about 60 KB; the same gradient checks the whole-run
  kernel, with each window as a run whose first steps are masked); every step's loss, gradient norm (before clipping) and learning rate are
  stored; then torch.nn.utils.clip_grad_norm_(max_norm) and torch.optim.Adam with the
  learning rate set before step k to lr * (1 + cos(pi k / steps)) / 2 (cosine decay to 0, as
  CosineAnnealingLR(T_max=steps, eta_min=0) in closed form); the parameters after the last
  step are stored.

Inputs, targets and start states are rounded to 6 decimals before use, so the file holds the
exact values PyTorch ran on. Computed values are written with 8 significant digits (the tests
compare at 1e-6 relative or looser, so the rounding, 5e-9 relative, does not matter), to keep
the file near 200 KB.

Run: python3 gen_pytorch_lstm_32.py > pytorch_lstm_5x32.json  (needs torch; CPU is enough).
"""

import json
import math
import sys

import torch
from torch import nn

I, H = 5, 32
DIGITS = 8


def sig(v):
    """A float with DIGITS significant digits (as a JSON number)."""
    return float(f"{v:.{DIGITS - 1}e}")


def tolist_sig(t):
    if t.dim() == 0:
        return sig(t.item())
    return [tolist_sig(r) for r in t]


def rounded(t):
    return torch.round(t * 1e6) / 1e6


torch.manual_seed(20240232)
torch.set_default_dtype(torch.float64)

lstm = nn.LSTM(I, H, batch_first=True)
head = nn.Linear(H, 1)
with torch.no_grad():
    for p in list(lstm.parameters()) + list(head.parameters()):
        p.copy_(torch.randint(-11, 12, p.shape).double() / 64.0)


def params_dict(sig_digits=False):
    f = tolist_sig if sig_digits else (lambda t: t.detach().tolist())
    return {
        "weight_ih": f(lstm.weight_ih_l0),
        "weight_hh": f(lstm.weight_hh_l0),
        "bias_ih": f(lstm.bias_ih_l0),
        "bias_hh": f(lstm.bias_hh_l0),
        "head_weight": f(head.weight),
        "head_bias": f(head.bias),
    }


# The initial params, exact (k/64), before any step changes them.
INITIAL = params_dict()


def grads_dict():
    return {
        "weight_ih": tolist_sig(lstm.weight_ih_l0.grad),
        "weight_hh": tolist_sig(lstm.weight_hh_l0.grad),
        "bias_ih": tolist_sig(lstm.bias_ih_l0.grad),
        "bias_hh": tolist_sig(lstm.bias_hh_l0.grad),
        "head_weight": tolist_sig(head.weight.grad),
        "head_bias": tolist_sig(head.bias.grad),
    }


def all_params():
    return list(lstm.parameters()) + list(head.parameters())


def run(x, h0, c0):
    """x: (B, T, I); h0, c0: (B, H). Returns y (B, T), h_n, c_n (B, H)."""
    out, (h_n, c_n) = lstm(x, (h0.unsqueeze(0), c0.unsqueeze(0)))
    return head(out).squeeze(-1), h_n.squeeze(0), c_n.squeeze(0)


def smooth_inputs(steps, phase):
    """Slow, chamber-like inputs: a temperature-like sine, its rate and three lag-like terms."""
    t = torch.arange(steps, dtype=torch.float64)
    base = torch.sin(2 * math.pi * t / 97.0 + phase)
    cols = [
        base,
        torch.cos(2 * math.pi * t / 97.0 + phase) * 0.6,
        torch.sin(2 * math.pi * t / 41.0 + 2 * phase) * 0.8,
        torch.tanh(base * 1.5) - 0.2,
        0.5 * torch.randn(steps),
    ]
    return rounded(torch.stack(cols, dim=1))


cases = []

# Case 1: zero state, 48 steps, random inputs; loss and gradients.
x1 = rounded(torch.randn(48, I))
t1 = rounded(0.5 * torch.randn(48))
for p in all_params():
    p.grad = None
z = torch.zeros(1, H)
y1, hn1, cn1 = run(x1.unsqueeze(0), z, z)
loss1 = ((y1.squeeze(0) - t1) ** 2).mean()
loss1.backward()
cases.append(
    {
        "name": "short_zero_state_with_gradients",
        "x": x1.tolist(),
        "h0": [0.0] * H,
        "c0": [0.0] * H,
        "y": tolist_sig(y1.squeeze(0)),
        "h_n": tolist_sig(hn1.squeeze(0)),
        "c_n": tolist_sig(cn1.squeeze(0)),
        "target": t1.tolist(),
        "loss": sig(loss1.item()),
    }
)

# Case 2: non-zero start state, 24 steps, forward only.
with torch.no_grad():
    x2 = rounded(torch.randn(24, I))
    h0 = rounded(0.3 * torch.randn(1, H))
    c0 = rounded(torch.randn(1, H))
    y2, hn2, cn2 = run(x2.unsqueeze(0), h0, c0)
cases.append(
    {
        "name": "nonzero_state_forward",
        "x": x2.tolist(),
        "h0": h0.squeeze(0).tolist(),
        "c0": c0.squeeze(0).tolist(),
        "y": tolist_sig(y2.squeeze(0)),
        "h_n": tolist_sig(hn2.squeeze(0)),
        "c_n": tolist_sig(cn2.squeeze(0)),
    }
)

# Case 3: zero state, 300 smooth steps, forward only (state carried over many steps).
with torch.no_grad():
    x3 = smooth_inputs(300, 0.3)
    y3, hn3, cn3 = run(x3.unsqueeze(0), z, z)
cases.append(
    {
        "name": "long_smooth_forward",
        "x": x3.tolist(),
        "h0": [0.0] * H,
        "c0": [0.0] * H,
        "y": tolist_sig(y3.squeeze(0)),
        "h_n": tolist_sig(hn3.squeeze(0)),
        "c_n": tolist_sig(cn3.squeeze(0)),
    }
)

# Minibatch: windows from one series, burn-in masked loss, clipped Adam with cosine decay.
WINDOW, BURN_IN, BATCH, STEPS = 40, 12, 4, 3
LR, CLIP = 5e-3, 1.0
series_x = smooth_inputs(200, 1.1)
series_t = rounded(0.8 * torch.tanh(series_x[:, 0] * 1.3 + 0.5 * series_x[:, 2]) + 0.1)
starts = [sorted(torch.randint(0, 200 - WINDOW + 1, (BATCH,)).tolist()) for _ in range(STEPS)]
# One window shorter than the others would need padding in PyTorch; all have WINDOW steps.
opt = torch.optim.Adam(all_params(), lr=LR, betas=(0.9, 0.999), eps=1e-8)
steps = []
mb_grad = None
for k, st in enumerate(starts):
    opt.zero_grad()
    xb = torch.stack([series_x[s : s + WINDOW] for s in st])
    tb = torch.stack([series_t[s : s + WINDOW] for s in st])
    zb = torch.zeros(BATCH, H)
    yb, _, _ = run(xb, zb, zb)
    mask = torch.zeros(BATCH, WINDOW)
    mask[:, BURN_IN:] = 1.0
    loss = (((yb - tb) ** 2) * mask).sum() / mask.sum()
    loss.backward()
    if k == 0:
        mb_grad = grads_dict()
    norm = torch.nn.utils.clip_grad_norm_(all_params(), CLIP)
    lr = LR * (1 + math.cos(math.pi * k / STEPS)) / 2
    for g in opt.param_groups:
        g["lr"] = lr
    opt.step()
    steps.append(
        {
            "starts": st,
            "loss_before_step": sig(loss.item()),
            "grad_norm_before_clip": sig(norm.item()),
            "lr": lr,
        }
    )
    print(f"minibatch step {k}: loss {loss.item():.6f}, grad norm {norm.item():.4f}", file=sys.stderr)

ref = {
    "source": f"torch {torch.__version__} nn.LSTM({I}, {H}, batch_first=True) + nn.Linear({H}, 1), "
    "float64; generator crates/gyrotherm/tests/data/gen_pytorch_lstm_32.py",
    "gate_order": "rows of weight_ih/weight_hh/bias_* are the gates i, f, g, o, H rows each",
    "equations": "i=s(Wii x+bii+Whi h+bhi) f=s(Wif x+bif+Whf h+bhf) g=tanh(Wig x+big+Whg h+bhg) "
    "o=s(Wio x+bio+Who h+bho) c'=f*c+i*g h'=o*tanh(c') y=w h'+b",
    "loss": "mean over counted steps of (y - target)^2",
    "digits": f"computed values rounded to {DIGITS} significant digits; inputs, targets and "
    "params are exact",
    "input_size": I,
    "hidden_size": H,
}
ref["params"] = INITIAL
ref["cases"] = cases
ref["minibatch"] = {
    "optimizer": f"clip_grad_norm_(max_norm={CLIP}) then torch.optim.Adam(betas=(0.9, 0.999), "
    f"eps=1e-8), lr before step k = {LR} * (1 + cos(pi k / {STEPS})) / 2",
    "window": WINDOW,
    "burn_in": BURN_IN,
    "batch": BATCH,
    "lr": LR,
    "clip_grad_norm": CLIP,
    "series_x": series_x.tolist(),
    "series_target": series_t.tolist(),
    "steps": steps,
    "grad_step0": mb_grad,
    "params_after": params_dict(sig_digits=True),
}
json.dump(ref, sys.stdout, separators=(",", ":"))
sys.stdout.write("\n")

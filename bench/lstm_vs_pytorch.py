"""PyTorch peer of `examples/train_minibatch.rs`: the same network (one LSTM layer of H
hidden units on 5 inputs, a linear read-out), the same minibatch truncated BPTT (B windows
of W steps per Adam step, the first K steps of each window out of the loss), Adam at lr 5e-3
with cosine decay, gradient norm clipped at 1, f32, on T threads. Only the wall time is
compared: the data are a random sequence of the example's length (the values do not change
the work).

    python bench/lstm_vs_pytorch.py HIDDEN STEPS BATCH WINDOW BURN_IN THREADS
"""

import sys
import time

import torch

hidden, steps, batch, window, burn_in, threads = (int(a) for a in sys.argv[1:7])
torch.set_num_threads(threads)
torch.manual_seed(0)
rows, n_in = 30000, 5
x_all = torch.randn(rows, n_in)
y_all = torch.randn(rows, 1)
lstm = torch.nn.LSTM(n_in, hidden)
out = torch.nn.Linear(hidden, 1)
params = list(lstm.parameters()) + list(out.parameters())
opt = torch.optim.Adam(params, lr=5e-3)
sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, T_max=steps)
gen = torch.Generator().manual_seed(1)
start = time.perf_counter()
first = last = None
for step in range(steps):
    starts = torch.randint(0, rows - window, (batch,), generator=gen)
    idx = starts[None, :] + torch.arange(window)[:, None]
    x = x_all[idx]  # (window, batch, n_in)
    y = y_all[idx]
    h, _ = lstm(x)
    pred = out(h)
    loss = torch.mean((pred[burn_in:] - y[burn_in:]) ** 2)
    opt.zero_grad()
    loss.backward()
    torch.nn.utils.clip_grad_norm_(params, 1.0)
    opt.step()
    sched.step()
wall = time.perf_counter() - start
print(
    f"pytorch {torch.__version__}: hidden {hidden}, {steps} Adam steps of {batch} windows x "
    f"{window} steps (burn-in {burn_in}), f32, {threads} threads"
)
print(f"training: {wall:.2f} s wall ({1000 * wall / steps:.1f} ms per Adam step)")

"""Train a network on railforce windows with PyTorch (numpy stands in where torch is absent).

    python examples/python/train_windows.py DATA_FOLDER
"""
import sys

import numpy as np

from railforce.torch import WindowDataset, batches

data = sys.argv[1] if len(sys.argv) > 1 else "data/demo"
train = WindowDataset(data, "train", window=20, label="centre", stride=2)  # leak-free split
test = WindowDataset(data, "test", window=20, label="centre")
try:
    import torch

    net = torch.nn.Sequential(torch.nn.Flatten(), torch.nn.Linear(20 * 21, 64), torch.nn.ReLU(),
                              torch.nn.Linear(64, 2))
    opt = torch.optim.Adam(net.parameters(), lr=1e-3)
    for epoch in range(5):
        train.set_epoch(epoch)  # fresh input noise every epoch, as railforce train draws it
        for x, y in torch.utils.data.DataLoader(train, batch_size=256, shuffle=True):
            opt.zero_grad()
            loss = torch.nn.functional.mse_loss(net(x), y)
            loss.backward()
            opt.step()
    predict = lambda x: net(torch.from_numpy(x)).detach().numpy()  # noqa: E731
except ImportError:  # numpy stands in: ridge regression on the flattened windows
    x, y = map(np.concatenate, zip(*batches(train, 4096, shuffle=False)))
    a = x.reshape(len(x), -1).astype(np.float64)
    w = np.linalg.solve(a.T @ a + 1.0 * np.eye(a.shape[1]), a.T @ y)
    predict = lambda x: x.reshape(len(x), -1) @ w  # noqa: E731

xt, yt = map(np.concatenate, zip(*batches(test, 4096, shuffle=False)))
pred = predict(xt)
r2 = 1 - ((pred - yt) ** 2).sum(0) / ((yt - yt.mean(0)) ** 2).sum(0)
rmse_kn = np.sqrt(((test.to_newtons(pred) - test.to_newtons(yt)) ** 2).mean(0)) / 1e3
for t, r, e in zip(test.targets, r2, rmse_kn):
    print(f"{t}: test R² {r:.3f}, RMSE {e:.2f} kN")

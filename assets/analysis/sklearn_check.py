"""Fits scikit-learn's SVR, GBDT and decision tree with railforce's settings on the windows a
railforce test wrote (train_x.csv, train_y.csv, test_x.csv, test_y.csv in the folder given as
the first argument) and prints their test R² as JSON. Used by tests/sklearn.rs (CI)."""
import json
import sys

import numpy as np
from sklearn.ensemble import GradientBoostingRegressor
from sklearn.metrics import r2_score
from sklearn.svm import SVR
from sklearn.tree import DecisionTreeRegressor

d = sys.argv[1]
load = lambda n: np.loadtxt(f"{d}/{n}.csv", delimiter=",", ndmin=2)
xtr, ytr, xte, yte = load("train_x"), load("train_y")[:, 0], load("test_x"), load("test_y")[:, 0]
models = {
    # gamma='scale' is railforce's 1 / (features · Var x); C, epsilon and tol as railforce.
    "svr": SVR(kernel="rbf", C=1.0, epsilon=0.1, gamma="scale", tol=1e-3),
    "gbdt": GradientBoostingRegressor(n_estimators=100, max_depth=3, learning_rate=0.1, random_state=0),
    "tree": DecisionTreeRegressor(max_depth=12, min_samples_leaf=5, random_state=0),
}
out = {k: float(r2_score(yte, m.fit(xtr, ytr).predict(xte))) for k, m in models.items()}
print(json.dumps(out))

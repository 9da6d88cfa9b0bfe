"""Shared fixtures: the real data folder, and seeding of numpy and torch."""

import os
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[1]


def shared_data_dir():
    """The real test data: ``$SKGESTURE_SHARED_DATA`` or ``<repo>/../shared/data``."""
    env = os.environ.get("SKGESTURE_SHARED_DATA")
    return Path(env) if env else REPO.parent / "shared" / "data"


@pytest.fixture(scope="session")
def shared_data():
    """Path of ``shared/data``; skips the test cleanly when it is absent."""
    path = shared_data_dir()
    if not path.is_dir():
        pytest.skip(f"real data folder {path} not present")
    return path


@pytest.fixture(autouse=True)
def _one_torch_thread():
    """Tiny networks train fastest on one thread (no oversubscription under xdist)."""
    try:
        import torch
    except ImportError:  # pragma: no cover
        yield
        return
    n_threads = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(n_threads)


@pytest.fixture(autouse=True)
def _seed_everything():
    """Seed the global RNGs so a test that forgets random_state stays repeatable."""
    np.random.seed(0)  # noqa: NPY002 - test isolation only
    try:
        import torch
    except ImportError:  # pragma: no cover
        return
    torch.manual_seed(0)

"""Neural tests run torch on one thread: the CI machine has 2 shared cores, and torch's
thread pool thrashes when another process uses the other core (measured 20x slower)."""

import pytest
import torch


@pytest.fixture(autouse=True)
def _one_torch_thread():
    n = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(n)

"""Random vectors of a given length: the direction of an error is random, its size is the profile's."""

from __future__ import annotations

import numpy as np


def random_vector(rng: np.random.Generator, length: float) -> np.ndarray:
    """A 3-vector of exactly ``length`` in a direction uniform on the sphere. Always draws (three
    normals), so what is drawn after it does not depend on whether ``length`` is zero."""
    v = rng.normal(size=3)
    return v * (length / np.linalg.norm(v))

"""Type aliases shared across curvefair."""

from __future__ import annotations

from typing import Literal

import numpy as np
import numpy.typing as npt

#: float64 array of any shape.
FloatArray = npt.NDArray[np.float64]
#: Anything ``np.asarray`` turns into a float array.
ArrayLike = npt.ArrayLike

ParamName = Literal["uniform", "chord", "centripetal"]
ClampName = Literal["g0", "g1", "g2"]

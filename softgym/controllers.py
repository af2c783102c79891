"""Deprecated: the env policies moved to :mod:`softgym.policies`.

``softgym.controllers`` sat beside :mod:`softgym.design.controller` (a design's
sinusoidal controller) under a confusable name; import
``from softgym.policies import Sinusoid`` instead. This alias will be removed.
"""

import warnings

from softgym.policies import Sinusoid

__all__ = ["Sinusoid"]

warnings.warn(
    "softgym.controllers is deprecated; import Sinusoid from softgym.policies",
    DeprecationWarning,
    stacklevel=2,
)

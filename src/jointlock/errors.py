"""Exception and warning types raised by jointlock.

Every error raised at the public boundary is one of these, and its message names the
argument (or file field), the value received, and what is allowed.
"""

from __future__ import annotations


class JointlockError(Exception):
    """Base class of every error jointlock raises on purpose."""


class ModelError(JointlockError, ValueError):
    """An arm model, a model file, or an argument describing one is invalid."""


class ConfigurationError(JointlockError, ValueError):
    """A joint-space array (q, dq, ...) has the wrong shape or non-finite values, a ChainState
    does not belong to the q given, or an ``rng`` is not a seed >= 0, a Generator or None."""


class ScenarioError(JointlockError, ValueError):
    """A scenario file or a command-line option is invalid."""


class InfeasibleError(JointlockError):
    """No solution satisfies the given limits; the message says which limit and by how much."""


class SingularityWarning(UserWarning):
    """A result was computed at or near a singular configuration and may be ill-conditioned."""


class CampaignError(JointlockError, ValueError):
    """A campaign file, one of its cases, or a campaign output folder (ledger) is invalid."""

"""The seed papers' scenarios and printed numbers, typed once.

Everything here is data copied from the papers (with the section, table or equation it comes
from), used by the library's defaults, ``jointlock reproduce``
(:func:`jointlock.jobs.reproduction.reproduce`), the tests and the docs, so a printed figure
exists in exactly one place.  Pure data: these modules import nothing from jointlock (the
lowest layer); the arms' own tables are the robot factories of :mod:`jointlock.robots`.

- :mod:`jointlock.papers.p000`: the halt strategy paper (000): §5's scenario on halt7
  (``SCENARIO``), q_best / q_sub, K, CP(q_sub) and the CP gain, eq. (39)'s judgment matrix,
  its AHP weights, Table 5's RI and the CR limit, and §5.2's halt-motion results.
- :mod:`jointlock.papers.p001`: velocity-jump compensation (001): no printed number
  survived (``PRINTED`` is empty); NOTES-001's task (``TASK``).
- :mod:`jointlock.papers.p002`: fault tolerance of puma6 (002): the worked examples E1-E5,
  example A (Figs. 5-8: absorbable ranges, gamma, q at gamma) and example B (eqs. 21-22).
- :mod:`jointlock.papers.p004`: singularities of canadarm7 (004): the virtual link lengths
  and Table 3 (configurations and det(J Jᵀ)).
- :data:`REFERENCES`: each seed's authors, title, venue and DOI.
"""

from . import p000, p001, p002, p004
from .references import REFERENCES

__all__ = ["REFERENCES", "p000", "p001", "p002", "p004"]

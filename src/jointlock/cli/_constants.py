"""The library's values that the subcommands' parsers name in their help and choices.

Copied here so that a parser is built, and ``jointlock <command> --help`` printed, without
importing the library (numpy, scipy and matplotlib behind it: most of a command's start-up);
the library itself is imported only once the options are parsed.  Each value says where it
comes from, and ``tests/test_startup.py`` checks that it still equals it (no drift).
"""

from __future__ import annotations

#: :data:`jointlock.robots.BUILTIN_ROBOTS`.
BUILTIN_ROBOTS: tuple[str, ...] = ("halt7", "canadarm7", "puma6")
#: :data:`jointlock.jobs.halt.MIN_N_SAMPLES`: fewest time samples of the halt objective.
MIN_N_SAMPLES = 11
#: :data:`jointlock.jobs.jump.KAPPA_UNIT`: unit of the jump's kappa.
KAPPA_UNIT = "rad^2/(s m^3)"
#: :data:`jointlock.jobs.jump.MAX_ORDER`: highest polynomial order of kappa(t).
MAX_ORDER = 9
#: :data:`jointlock.jobs.jump.DEFAULT_ORDER`, :data:`jointlock.jobs.jump.DEFAULT_SWEEP`.
DEFAULT_ORDER = 5
DEFAULT_SWEEP = 40
#: :data:`jointlock.planning.replan.DEFAULT_STEP_WEIGHT` [m/rad^2].
DEFAULT_STEP_WEIGHT = 0.5
#: :data:`jointlock.scenario.MAX_ABS_DEG` [deg].
MAX_ABS_DEG = 360.0
#: :data:`jointlock.scenario.JOB_ORDER`.
JOB_ORDER: tuple[str, ...] = ("halt_config", "halt", "jump", "tolerance_angle", "replan", "workspace", "singular")
#: :data:`jointlock.jobs.reproduction.PAPERS`.
PAPERS: tuple[str, ...] = ("000", "001", "002", "004")
#: :data:`jointlock.analysis.singularity.BASE_KINDS`, :data:`~jointlock.analysis.singularity.RANK_TOL`.
SINGULAR_BASE_KINDS: tuple[str, ...] = ("fixed", "floating", "virtual")
RANK_TOL = 1e-8
#: :data:`jointlock.analysis.workspace.MIN_SAMPLES`: fewest workspace samples per arm.
WORKSPACE_MIN_SAMPLES = 1000
#: :data:`jointlock.jobs.tolerance_angle.MAX_GAMMA_SAMPLES`: most gamma samples of one sweep
#: (checked before the job runs, to name the options).
MAX_GAMMA_SAMPLES = 200_000

"""``lenscompare check``: declarative accuracy checks for other people's CI."""

from .config import CHECK_TYPES, DEFAULT_CONFIG, Check, load_checks
from .junit import write_junit
from .run import CheckResult, run_check

__all__ = ["CHECK_TYPES", "DEFAULT_CONFIG", "Check", "CheckResult", "load_checks", "run_check", "write_junit"]

"""Makes ``blocking_helpers`` importable by the test modules here (importlib import mode
puts no test directory on ``sys.path``)."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

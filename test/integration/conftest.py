"""The integration tests share bench/'s helpers that run FlexBE's onboard system (Operator,
OnboardSystem: bench/bench_flexbe_onboard.py runs them 100 times): bench/ is on their path."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / 'bench'))

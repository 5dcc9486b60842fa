"""`python -m training.evaluate` is the evaluation command as DESIGN.md names it, a contract that
outlives the package layout; the command itself is training/evaluation/evaluate.py."""
import sys

from .evaluation.evaluate import main

if __name__ == "__main__":
    sys.exit(main())

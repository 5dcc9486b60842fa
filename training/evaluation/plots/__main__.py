"""`python -m training.evaluation.plots`: every figure, or those --only names."""
import sys

from . import main

sys.exit(main())

"""`python -m renderer` is the `renderer` command."""

import sys

from renderer.cli import main

sys.exit(main())

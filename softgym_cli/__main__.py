"""``python -m softgym_cli``: the ``softgym`` command."""

import sys

from softgym_cli.parser import main

sys.exit(main())

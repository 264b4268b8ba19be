import sys

from gateware.cli import main

sys.exit(main())

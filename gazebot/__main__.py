import sys

from gazebot.cli import main

sys.exit(main())

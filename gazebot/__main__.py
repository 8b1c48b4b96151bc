import sys

from gazebot.apps.cli import main

sys.exit(main())

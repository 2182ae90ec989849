import sys

from monopic.cli.main import main

sys.exit(main())

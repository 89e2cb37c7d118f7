from retro.cli import main

raise SystemExit(main())

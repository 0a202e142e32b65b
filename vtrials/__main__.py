from vtrials.cli import main

raise SystemExit(main())

from gearcheck.cli import main

raise SystemExit(main())

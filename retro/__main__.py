try:
    from retro.entry import main
except KeyboardInterrupt:  # Ctrl-C in the few milliseconds before retro.entry installs its handlers
    import sys

    sys.stderr.write("retro: interrupted\n")
    raise SystemExit(130) from None

raise SystemExit(main())

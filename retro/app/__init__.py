"""What each CLI command does, as functions: load inputs, run the core, shape the results.

The CLI (retro/cli/) and the demo (retro/demo/) call these; they hold no argument parsing and no printing.
"""

"""What each `retro` command does, one function per command, taking plain arguments and returning data.

Each module is named after its command and holds that function (`asm.asm`, `run.run`, `vic.vic`,
`nes.nes`, `check.check`, `check.cycles`, `chart.chart`, `stability.stability`, `advise.advise`,
`parry.parry`, `demo.demo`) and the text (`lines`) and, where the command has one, the JSON
(`as_json`) of its result. Numbers may be given as ints or as the text a user typed ("$C000",
"0x10"): each function checks its own arguments, once, and names the option in its error.
Each module also holds its command-line face beside the function: `HELP`, `add_options(parser)` and
`main(args)`, which calls the function and prints (shared options: `options.py`). `retro.cli` only
lists the modules; `retro demo` is a list of calls to the functions.
"""

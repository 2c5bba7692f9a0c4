"""The code of tools/bench (the executable entry point, which only calls
cli.main), one concern a module:

  cli.py      the command line (its docstring is the tool's description) and main
  configs.py  the configurations a scene is rendered in
  scenes.py   the benchmark scenes and the scene copies renders read
  runner.py   running pyrolume: references, measured renders, compare, machine
  stats.py    medians, efficiency, equal-time relMSE
  report.py   the CSV's columns and the markdown between the bench markers
  plot.py     the error-against-time plot
  common.py   the repository root, the log, JSON files, file stamps
"""

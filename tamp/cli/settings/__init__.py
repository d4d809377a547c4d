"""The edge of the ``tamp`` command line: for each converted command, the one function that turns
the parsed argparse namespace into the typed settings the command runs with (refusing option
combinations that would do nothing, in one line), and the recorded configuration built from
those settings. `run`: ``tamp run`` and ``tamp demo``; `plan`: ``tamp plan``, ``example`` and
``validate``. Below these functions no code sees the namespace
(``tests/tamp/cli/test_cli_edge.py``)."""

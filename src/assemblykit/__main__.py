"""``python -m assemblykit``: the ``assemblykit`` command (:func:`assemblykit.cli.main`)."""

from assemblykit.cli import main

main()

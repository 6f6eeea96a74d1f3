"""The command-line scripts (``python scripts/<name>.py`` or the ``puzzlebox-<name>`` console commands): each
parses its flags, calls :mod:`puzzlebox.lab`, and maps the library's errors to one line and exit 2."""

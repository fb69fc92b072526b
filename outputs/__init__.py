"""What a command or a study writes: its result on standard output alone (``outputs.stdout``) and
the files it writes, never over another's by accident (``outputs.files``)."""

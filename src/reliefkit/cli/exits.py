"""Exit statuses of the command line (docs/cli.md)."""

EXIT_INPUT, EXIT_USAGE, EXIT_INTERNAL = 1, 2, 3
EXIT_INTERRUPTED = 130  # what a shell reports for a process stopped by SIGINT
EXIT_BROKEN_PIPE = 141  # what a shell reports for a process stopped by SIGPIPE
EXIT_TERMINATED = 143   # what a shell reports for a process stopped by SIGTERM

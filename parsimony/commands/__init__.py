"""One module per `parsimony` subcommand, each with `add_parser(subparsers)` and `run(args)`."""

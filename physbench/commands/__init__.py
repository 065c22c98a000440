"""One module per subcommand: ``add_arguments(parser)`` (cheap, stdlib only at import) and
``main(args) -> int`` (imports what it needs)."""

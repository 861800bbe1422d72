"""The ``sixdof`` commands, one module each: ``main(args, workers)`` reads the parsed arguments, calls a workflow
(:mod:`sixdof.workflows`) and prints. :func:`sixdof.cli.main` imports only the module of the command given, once
the arguments are parsed and a drawing command's figure workers have started: ``sixdof plot`` loads no JAX,
``sixdof --help`` none of them."""

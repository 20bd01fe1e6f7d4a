"""The arena's geometry that both configuration and engine need: obstacle shapes (``obstacles``) and the
neighbour grid's cells (``grid``).  Pure functions, importing nothing else of the package, so ``config``
can check a setup and ``engine`` can run it without either importing the other."""

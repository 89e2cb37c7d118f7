"""Coverage reports of a check: the annotated listing, LCOV and HTML (docs/coverage.md), one module per
format over the rows of `annotated`."""

"""Tests of infomarket.chain (a package, so its module names cannot clash with tests elsewhere)."""

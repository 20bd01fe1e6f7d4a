"""Tests of infomarket.evm (a package, so its module names cannot clash with tests elsewhere)."""

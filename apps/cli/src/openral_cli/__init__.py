"""The openral command line."""

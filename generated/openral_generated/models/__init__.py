# GENERATED from schema/ by `just schema-export` -- do not edit.
"""Pydantic models of the contract, one module per schema file."""

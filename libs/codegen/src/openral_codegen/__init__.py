"""Schema export: derive generated/ and the docs reference from schema/ and robots/.

``just schema-export`` runs :func:`export`; ``just schema-check`` runs :func:`check`.
"""

from openral_codegen.export import check, export

__all__ = ["check", "export"]

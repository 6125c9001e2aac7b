"""``--namespace``: the ROS namespace a graph runs under, and a client talks to.

``deploy sim|real --namespace NS`` puts every name of the graph under ``/NS``; ``rskill run``
and ``rskill trajectory`` with the same option talk to that graph (for example deploy real
under ``/real`` beside the robot's own driver at the root).
"""

from __future__ import annotations

from typing import Annotated

import typer
from openral_core.errors import OpenralError

Namespace = Annotated[
    str,
    typer.Option(
        "--namespace",
        help="The graph's ROS namespace (/arm: /arm/joint_states, ...).",
    ),
]


def bad_namespace(namespace: str, error: Exception) -> OpenralError:
    """One line for a namespace ROS refuses (rclpy's InvalidNamespaceException and kin)."""
    return OpenralError(f"--namespace {namespace!r}: {error}".splitlines()[0])


def checked(namespace: str) -> str:
    """``namespace`` when ROS takes it (``arm`` and ``/arm`` alike; ``""``: the root).

    Raises:
        OpenralError: One line naming what ROS refuses in it.
    """
    if not namespace:
        return namespace
    from rclpy.validate_namespace import validate_namespace

    try:
        validate_namespace(namespace if namespace.startswith("/") else f"/{namespace}")
    except Exception as error:  # rclpy's InvalidNamespaceException
        raise bad_namespace(namespace, error) from None
    return namespace

"""``openral ros services``, ``actions`` and ``nodes``: what the graph offers, like
``ros2 service list -t``, ``ros2 action list -t`` and ``ros2 node list``.

Discovery waits as ``openral ros topics`` does; the listing itself is
:mod:`openral_nodes.graph_listing`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Annotated

import typer

from openral_cli.commands.ros import LATE_DISCOVERY_S, DiscoveryWait, DomainId, _probe_node, app
from openral_cli.console import err, out
from openral_cli.ros_available import require_ros

if TYPE_CHECKING:
    from openral_nodes.graph_listing import GraphListing, Interface


@app.command("services")
def services(
    wait: DiscoveryWait = 2.0,
    all_services: Annotated[
        bool,
        typer.Option(
            "--all", help="Include hidden services (a name part starting with _): /_action/ ones."
        ),
    ] = False,
    domain_id: DomainId = None,
) -> None:
    """Table of the services in the graph: name and type(s)."""
    require_ros()
    listing, domain, waited = _listing(wait, domain_id, all_services)
    _print_interfaces("service", listing.services, domain, waited)


@app.command("actions")
def actions(wait: DiscoveryWait = 2.0, domain_id: DomainId = None) -> None:
    """Table of the actions in the graph: name and type(s), found from the hidden
    feedback topic (NAME/_action/feedback) each action server publishes."""
    require_ros()
    listing, domain, waited = _listing(wait, domain_id, include_hidden=False)
    _print_interfaces("action", listing.actions, domain, waited)


@app.command("nodes")
def nodes(
    wait: DiscoveryWait = 2.0,
    all_nodes: Annotated[
        bool, typer.Option("--all", help="Include hidden nodes (a name starting with _).")
    ] = False,
    domain_id: DomainId = None,
) -> None:
    """Table of the nodes in the graph (but this command's own): full name and namespace."""
    require_ros()
    listing, domain, waited = _listing(wait, domain_id, all_nodes)
    rows = [(node.full_name, node.namespace) for node in listing.nodes]
    _print_table("node", ("node", "namespace"), rows, domain, waited)


def _listing(
    wait: float, domain_id: int | None, include_hidden: bool
) -> tuple[GraphListing, int, float]:
    """The graph once discovery settled (hidden names only if ``include_hidden``), its
    domain and the seconds waited."""
    from openral_nodes.graph_listing import settled_listing

    with _probe_node(domain_id) as node:
        listing, waited = settled_listing(node, wait_s=wait, longest_s=wait + LATE_DISCOVERY_S)
        domain = node.context.get_domain_id()
    return listing.shown(include_hidden), domain, waited


def _print_interfaces(
    kind: str, interfaces: Sequence[Interface], domain: int, waited: float
) -> None:
    from openral_core.errors import escaped

    rows = [(item.name, ", ".join(map(escaped, item.types))) for item in interfaces]
    _print_table(kind, (kind, "type"), rows, domain, waited)


def _print_table(
    kind: str,
    columns: tuple[str, str],
    rows: Sequence[tuple[str, str]],
    domain: int,
    waited: float,
) -> None:
    """``rows`` under ``columns``, titled with the domain; one line on stderr when none."""
    from rich.table import Table

    if not rows:
        err.print(f"no {kind}s on ROS_DOMAIN_ID={domain} after {waited:.1f} s", highlight=True)
        return
    table = Table(title=f"ROS_DOMAIN_ID={domain}")
    table.add_column(columns[0], no_wrap=True)
    table.add_column(columns[1], overflow="fold")
    for row in rows:
        table.add_row(*row)
    out.print(table)

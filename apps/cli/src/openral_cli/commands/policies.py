"""``openral sim policies``: the policies ``sim sweep`` and ``rskill run`` build by name.

Example::

    openral sim policies
"""

from __future__ import annotations

from openral_cli.console import out


def policies() -> None:
    """List the policies buildable by name (built-in, then installed plug-ins) with each
    one's -p parameters and defaults. A class in a file or module needs no listing:
    --policy my_policy.py:Wave."""
    from openral_eval.policies import available_policies
    from rich.table import Table

    table = Table(title="policies (--policy NAME, -p key=value)", title_justify="left")
    for column in ("policy", "from", "parameters (defaults)"):
        table.add_column(column)
    for listing in available_policies():
        parameters = ", ".join(f"{key}={value}" for key, value in listing.parameters)
        table.add_row(listing.name, listing.source, listing.problem or parameters or "none")
    out.print(table, soft_wrap=False)
    out.print("A class of your own: --policy my_policy.py:ClassName or package.module:ClassName")

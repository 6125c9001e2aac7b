"""The docs site builds strictly, has its features, and its reference covers every schema."""

from __future__ import annotations

import importlib
import json
import re
from typing import Any

import pytest
from openral_codegen.robot_docs import NAV_BEGIN, NAV_END
from openral_codegen.rule_examples import RULE_BREAKS, numbered_rules, rule_examples
from openral_codegen.schema_docs import PAGES, read_schemas
from openral_core.registry import robot_ids
from openral_core.schemas import SchemaName

from tests.conftest import REPO, ROBOTS
from tests.docs.conftest import BuiltSite

DOCS = REPO / "docs"


def page_files(name: SchemaName) -> list[str]:
    """File names (inside docs/reference/) of the pages that document schema ``name``."""
    return [f"{page.slug}.md" for page in PAGES if page.schema is name]


def property_names(schema: dict[str, Any]) -> set[str]:
    """Every property name declared anywhere in ``schema``."""
    names: set[str] = set()

    def walk(node: Any) -> None:
        if isinstance(node, dict):
            names.update(node.get("properties", {}))
            for value in node.values():
                walk(value)
        elif isinstance(node, list):
            for item in node:
                walk(item)

    walk(schema)
    return names


def test_mkdocs_build_strict_succeeds(built_site: BuiltSite) -> None:
    assert built_site.returncode == 0, built_site.log
    for page in (
        "index.html",
        "architecture/index.html",
        "reference/robot/index.html",
        "reference/grippers/index.html",
        "robots/index.html",
        "robots/franka_panda/index.html",
        "tutorials/add-a-robot/index.html",
    ):
        assert (built_site.site / page).is_file(), f"site lacks {page}"


def test_site_has_search_dark_mode_code_copy_and_edit_links(built_site: BuiltSite) -> None:
    index = json.loads((built_site.site / "search" / "search_index.json").read_text())
    assert any("franka_panda" in doc["location"] for doc in index["docs"])
    html = (built_site.site / "robots" / "franka_panda" / "index.html").read_text()
    assert 'data-md-color-scheme="slate"' in html  # the dark palette's toggle
    assert "content.code.copy" in html
    assert "edit/main/docs/robots/franka_panda.md" in html


def test_robot_page_shows_its_picture(built_site: BuiltSite) -> None:
    html = (built_site.site / "robots" / "franka_panda" / "index.html").read_text()
    assert re.search(r'<img [^>]*src="\.\./\.\./images/robots/franka_panda\.png"', html)
    assert (built_site.site / "images" / "robots" / "franka_panda.png").is_file()


@pytest.mark.parametrize("name", list(SchemaName), ids=str)
def test_reference_pages_list_every_schema_property(name: SchemaName) -> None:
    schemas = read_schemas(REPO / "schema")
    text = "".join((DOCS / "reference" / f).read_text() for f in page_files(name))
    missing = [p for p in sorted(property_names(schemas[name])) if f"| `{p}`<br>" not in text]
    assert not missing, f"the reference pages of {name.file_name} lack {missing}"


def test_every_numbered_rule_has_a_broken_example() -> None:
    for name in SchemaName:
        comment = read_schemas(REPO / "schema")[name].get("$comment", "")
        numbers = set(numbered_rules(comment)[1])
        shown = {b.rule for b in RULE_BREAKS if b.schema is name}
        assert numbers <= shown, f"{name.file_name}: add RULE_BREAKS for {numbers - shown}"


def test_reference_shows_the_errors_the_validator_prints_now() -> None:
    text = "".join((DOCS / "reference" / f).read_text() for f in ("robot.md", "scene.md"))
    for example in rule_examples(REPO):
        assert f"```text\n{example.error}\n```" in text, example.broken.rule


def test_every_robot_has_a_page_and_a_nav_entry() -> None:
    config = (REPO / "mkdocs.yml").read_text()
    nav = config[config.index(NAV_BEGIN) : config.index(NAV_END)]
    for robot_id in robot_ids(ROBOTS):
        assert (DOCS / "robots" / f"{robot_id}.md").is_file(), robot_id
        assert f"robots/{robot_id}.md" in nav, robot_id


def test_architecture_page_names_only_modules_and_functions_that_exist() -> None:
    text = (DOCS / "architecture.md").read_text()
    names = sorted(set(re.findall(r"`(openral_\w+(?:\.\w+)*)`", text)))
    assert len(names) > 15
    missing = []
    for name in names:
        parts = name.split(".")
        for cut in range(len(parts), 0, -1):
            try:
                target: object = importlib.import_module(".".join(parts[:cut]))
            except ModuleNotFoundError:
                continue
            try:
                for attribute in parts[cut:]:
                    target = getattr(target, attribute)
            except AttributeError:
                missing.append(name)
            break
        else:
            missing.append(name)
    assert not missing, f"docs/architecture.md names what does not exist: {missing}"

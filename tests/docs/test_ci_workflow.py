"""The repository host's workflow stays in step with the project's own CI and docs build:
its test job runs ``.ci/run`` (the README's test command, then the checks), its docs job
builds the site with the justfile's strict ``docs`` recipe and publishes it from main only,
and the README links the site mkdocs.yml names."""

from __future__ import annotations

from typing import Any

import yaml

from tests.conftest import REPO

WORKFLOW = REPO / ".github" / "workflows" / "ci.yml"


def _workflow() -> dict[str, Any]:
    data: dict[str, Any] = yaml.safe_load(WORKFLOW.read_text())
    return data


def _runs(job: dict[str, Any]) -> list[str]:
    return [str(step["run"]) for step in job["steps"] if "run" in step]


def test_the_test_job_runs_ci_run_which_runs_the_readmes_test_command() -> None:
    jobs = _workflow()["jobs"]
    assert "bash .ci/run" in _runs(jobs["test"])
    ci_run = (REPO / ".ci" / "run").read_text()
    assert "./bootstrap test" in ci_run and "./bootstrap test" in (REPO / "README.md").read_text()
    assert jobs["test"]["timeout-minutes"] <= 90


def test_the_docs_job_builds_strictly_and_publishes_from_main_after_the_tests() -> None:
    workflow = _workflow()
    docs = workflow["jobs"]["docs"]
    assert docs["needs"] == "test"
    assert "refs/heads/main" in docs["if"] and "push" in docs["if"]
    assert "./bootstrap docs" in _runs(docs)
    justfile = (REPO / "justfile").read_text()
    recipe = justfile[justfile.index("\ndocs:") :].split("\n\n")[0]
    assert "mkdocs build --strict --site-dir site" in recipe
    uses = [step.get("uses", "") for step in docs["steps"]]
    assert any(u.startswith("actions/upload-pages-artifact") for u in uses)
    assert any(u.startswith("actions/deploy-pages") for u in uses)
    assert workflow[True]["push"]["branches"] == ["main"]  # YAML reads `on:` as True


def test_the_readme_links_the_published_site() -> None:
    site = yaml.safe_load((REPO / "mkdocs.yml").read_text().split("\ntheme:")[0])["site_url"]
    assert site.startswith("https://") and site in (REPO / "README.md").read_text()

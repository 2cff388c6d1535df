"""The README's node tables match what the nodes declare."""

from node_docs import main as node_docs
from swivel_car_testing import REPO_ROOT


def test_readme_node_tables_are_current():
    assert node_docs(['--check', str(REPO_ROOT / 'README.md')]) == 0, (
        'run: scripts/in_ws python scripts/node_docs.py --write README.md')

"""What nbval compares, for tests that run notebooks themselves (several kernels at once).

Uses nbval's own stream coalescing and its sanitize-file parser, with tests/sanitize.cfg,
so "the same outputs" means here what it means in ``make test``.
"""

from __future__ import annotations

import asyncio
import copy
import os
from pathlib import Path
from typing import Optional

import nbformat
from nbclient import NotebookClient
from nbval.plugin import coalesce_streams, get_sanitize_patterns

from ros2nb.temporary import owned_folder

ROOT = Path(__file__).resolve().parent.parent
PATTERNS = get_sanitize_patterns((ROOT / 'tests' / 'sanitize.cfg').read_text())
IGNORED = 'nbval-ignore-output'


def sanitize(text: str) -> str:
    import re
    for regex, replace in PATTERNS:
        text = re.sub(regex, replace, text)
    return text


def comparable_outputs(outputs: list) -> list[str]:
    """What nbval compares of one cell's outputs: sanitized streams (joined as nbval joins
    them), errors, and the text of displays (nbval skips their images too)."""
    def one(output: dict) -> nbformat.NotebookNode:
        output = copy.deepcopy(output)
        if isinstance(output.get('text'), list):  # as stored in a file: a list of lines
            output['text'] = ''.join(output['text'])
        for key, value in output.get('data', {}).items():
            if isinstance(value, list):
                output['data'][key] = ''.join(value)
        return nbformat.from_dict(output)

    # the display long work showed and emptied when it ended (ros2nb.working): whether one
    # was made depends on how long the work took; make solutions drops it, nbval skips it
    kept = [o for o in outputs if not (o.get('output_type') == 'display_data'
                                       and not o.get('data'))]
    joined = coalesce_streams([one(o) for o in kept])
    return [sanitize(f'{o.name}: {o.text}') if o.output_type == 'stream' else
            f'error: {o.ename}: {sanitize(o.evalue)}' if o.output_type == 'error'
            else f'{o.output_type}: {sanitize(str(o.get("data", {}).get("text/plain", "")))}'
            for o in joined]


def compared(cell: dict) -> bool:
    """True for the code cells nbval compares (not tagged ``nbval-ignore-output``)."""
    return cell['cell_type'] == 'code' and IGNORED not in cell['metadata'].get('tags', [])


def comparable(nb: nbformat.NotebookNode) -> dict[int, list[str]]:
    """Per code cell that nbval compares: its sanitized stream texts and error names."""
    return {index: comparable_outputs(cell.get('outputs', []))
            for index, cell in enumerate(nb.cells) if compared(cell)}


def differences(stored: nbformat.NotebookNode, ran: nbformat.NotebookNode) -> list[str]:
    """The cells whose outputs differ, each as ``cell N: stored ... got ...``."""
    want, got = comparable(stored), comparable(ran)
    return [f'cell {i}: stored {want[i]!r:.300} got {got.get(i)!r:.300}'
            for i in want if got.get(i) != want[i]]


def kernel_env(parent: Path, domain: Optional[int] = None) -> dict[str, str]:
    """A kernel's environment: a workspace of its own (a new learner's) under ``parent`` (a
    test's ``tmp_path``, which pytest removes), in a folder that tests/sanitize.cfg masks;
    no ROS domain unless one is forced."""
    env = {k: v for k, v in os.environ.items() if k != 'ROS_DOMAIN_ID'}
    scratch = owned_folder('ros2nb-test-', parent)
    env['ROS2NB_WORKSPACE'] = str(scratch / 'ROS2_and_RL_Tutorials')
    if domain is not None:
        env['ROS_DOMAIN_ID'] = str(domain)
    return env


async def _run(nb: nbformat.NotebookNode, env: dict[str, str], timeout: float) -> None:
    client = NotebookClient(nb, timeout=timeout, kernel_name='python3',
                            resources={'metadata': {'path': str(ROOT / 'solutions')}})
    await client.async_execute(env=env)


def run_at_once(jobs: list[tuple[nbformat.NotebookNode, dict[str, str]]],
                timeout: float = 600) -> None:
    """Execute notebooks in place, each in its own kernel, all at the same time."""
    async def together() -> None:
        await asyncio.gather(*(_run(nb, env, timeout) for nb, env in jobs))
    asyncio.run(together())

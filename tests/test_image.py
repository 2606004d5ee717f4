"""The course as an image (environment/Containerfile): built, started, reached, and run.

``make image`` builds it with podman on a Debian 12 base that debootstrap makes (image
registries may be out of reach; the base is kept in podman's store for the next run), the
container starts JupyterLab on the learner's notebooks, the host reaches it with the token it
printed, and nbval runs one notebook inside it.  Needs root, podman, runc and debootstrap
(``make test`` installs them as root: its ``image-tool``); otherwise it skips.
"""

import json
import os
import re
import shutil
import subprocess
import tempfile
import urllib.request
from pathlib import Path
from typing import Optional

import pytest

from ros2nb.patience import wait_for_work
from waiting import run_to_end

ROOT = Path(__file__).resolve().parent.parent
BASE = 'localhost/ros2nb-debian-bookworm-minbase:latest'
TAG = 'localhost/ros2-course-test:latest'
#: This machine's podman settings (Debian's crun refuses its hybrid cgroups: runc).
CONF = ROOT / 'environment' / 'containers.conf'

#: The longest the build, the base's debootstrap and the lab's start may each take: of the
#: work of their processes, or of their idle waiting (tests/waiting.py), so that a cold build
#: beside CPU burners is slow, never cut.
BUILD_PATIENCE_S = 900
pytestmark = [
    pytest.mark.image,
    pytest.mark.timeout(4 * 3600),  # a hang's bound: each wait below counts work
    pytest.mark.skipif(os.geteuid() != 0 or not all(shutil.which(t) for t in
                                                     ('podman', 'runc', 'debootstrap')),
                       reason='needs root, podman, runc and debootstrap (make test installs '
                              'them as root)'),
]


def podman(*args: str, check: bool = True, timeout: float = 600) -> subprocess.CompletedProcess:
    env = dict(os.environ, CONTAINERS_CONF=str(CONF))
    return subprocess.run(['podman', *args], env=env, capture_output=True, text=True,
                          check=check, timeout=timeout)


def debian_base() -> None:
    """A minbase Debian 12 in podman's store, made once by debootstrap (as a newcomer's machine)."""
    if podman('image', 'exists', BASE, check=False).returncode == 0:
        return
    with tempfile.TemporaryDirectory() as rootfs:
        made = run_to_end(['debootstrap', '--variant=minbase', 'bookworm', rootfs,
                           'http://deb.debian.org/debian'], 'debootstrap of the base',
                          seconds=BUILD_PATIENCE_S)
        assert made.returncode == 0, (made.stdout + made.stderr)[-3000:]
        tar = subprocess.Popen(['tar', '-C', rootfs, '-c', '.'], stdout=subprocess.PIPE)
        subprocess.run(['podman', 'import', '-', BASE], stdin=tar.stdout, check=True,
                       capture_output=True, env=dict(os.environ, CONTAINERS_CONF=str(CONF)))
        tar.wait()


def test_the_image_opens_the_learners_lab_and_runs_a_notebook():
    debian_base()
    tag = TAG  # kept between runs: its layers are the next build's cache
    built = run_to_end(['make', '--no-print-directory', 'image', f'IMAGE={tag}', f'BASE={BASE}',
                        'PULL=never'], 'make image', seconds=BUILD_PATIENCE_S, cwd=ROOT,
                       env=dict(os.environ, CONTAINERS_CONF=str(CONF)))
    assert built.returncode == 0, built.stdout[-3000:] + built.stderr[-3000:]
    podman('image', 'prune', '-f', check=False)  # the layers of earlier builds no tag holds
    name, volume = f'ros2-course-test-{os.getpid()}', f'ros2-course-test-work-{os.getpid()}'
    try:
        podman('run', '-d', '--name', name, '-p', '127.0.0.1::8888', '-v',
               f'{volume}:/home/learner/work', tag)
        port = podman('port', name, '8888').stdout.strip().rsplit(':', 1)[-1]
        inside = int(podman('inspect', '--format', '{{.State.Pid}}', name).stdout.strip())
        logs = podman('logs', name, check=False)

        def url() -> Optional[str]:  # the lab says its URL when up
            nonlocal logs
            logs = podman('logs', name, check=False)
            found = re.search(r'/lab\?token=([0-9a-f]+)', logs.stdout + logs.stderr)
            return found.group(1) if found else None

        # the container's processes are the podman daemon's, not this test's: watched by pid
        assert wait_for_work(url, [inside], BUILD_PATIENCE_S), (logs.stdout + logs.stderr)[-3000:]
        token = url()
        with urllib.request.urlopen(f'http://127.0.0.1:{port}/api/contents?token={token}',
                                    timeout=30) as reply:
            names = {item['name'] for item in json.load(reply)['content']}
        assert '03-write-the-publisher.ipynb' in names, names  # the learner's copies, in the volume
        inside = podman('exec', name, 'bash', '-c',
                        'cd /opt/ros2-course && .venv/bin/python -m pytest -q '
                        '--nbval solutions/04-write-the-subscriber.ipynb --nbval-current-env '
                        '--nbval-sanitize-with tests/sanitize.cfg', check=False)
        assert inside.returncode == 0, inside.stdout[-3000:]
        # Zero to JupyterHub's single-user command (docs/classroom-server.md) is in the image
        hub = podman('exec', name, '/opt/ros2-course/.venv/bin/jupyterhub-singleuser',
                     '--version', check=False)
        assert hub.returncode == 0, hub.stderr
    finally:
        podman('rm', '-f', name, check=False)
        podman('volume', 'rm', '-f', volume, check=False)

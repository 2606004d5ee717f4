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
import time
import urllib.request
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
BASE = 'localhost/ros2nb-debian-bookworm-minbase:latest'
TAG = 'localhost/ros2-course-test:latest'
#: This machine's podman settings (Debian's crun refuses its hybrid cgroups: runc).
CONF = ROOT / 'environment' / 'containers.conf'

pytestmark = [
    pytest.mark.image,
    pytest.mark.timeout(1200),
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
        subprocess.run(['debootstrap', '--variant=minbase', 'bookworm', rootfs,
                        'http://deb.debian.org/debian'], check=True, capture_output=True,
                       timeout=900)
        tar = subprocess.Popen(['tar', '-C', rootfs, '-c', '.'], stdout=subprocess.PIPE)
        subprocess.run(['podman', 'import', '-', BASE], stdin=tar.stdout, check=True,
                       capture_output=True, env=dict(os.environ, CONTAINERS_CONF=str(CONF)))
        tar.wait()


def test_the_image_opens_the_learners_lab_and_runs_a_notebook():
    debian_base()
    tag = TAG  # kept between runs: its layers are the next build's cache
    built = subprocess.run(['make', '--no-print-directory', 'image', f'IMAGE={tag}', f'BASE={BASE}',
                            'PULL=never'], cwd=ROOT, capture_output=True, text=True, timeout=1200,
                           env=dict(os.environ, CONTAINERS_CONF=str(CONF)))
    assert built.returncode == 0, built.stdout[-3000:] + built.stderr[-3000:]
    podman('image', 'prune', '-f', check=False)  # the layers of earlier builds no tag holds
    name, volume = f'ros2-course-test-{os.getpid()}', f'ros2-course-test-work-{os.getpid()}'
    try:
        podman('run', '-d', '--name', name, '-p', '127.0.0.1::8888', '-v',
               f'{volume}:/home/learner/work', tag)
        port = podman('port', name, '8888').stdout.strip().rsplit(':', 1)[-1]
        token = None
        deadline = time.monotonic() + 300
        while token is None and time.monotonic() < deadline:  # the lab says its URL when up
            logs = podman('logs', name, check=False)
            found = re.search(r'/lab\?token=([0-9a-f]+)', logs.stdout + logs.stderr)
            token = found.group(1) if found else None
            time.sleep(0.5)
        assert token, (logs.stdout + logs.stderr)[-3000:]
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

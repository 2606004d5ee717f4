"""JupyterHub for a class on one machine: ``make hub`` (docs/classroom-server.md).

Learners log in with their Unix account and password (PAM). Each gets a Jupyter server of
their own, started as that Unix user by ``LocalProcessSpawner`` from the course's venv, so
every learner has the course's kernel, ros2nb and ROS 2 Jazzy. ``ros2nb_instructor.hub.singleuser``
runs first, as the learner: it copies the learner notebooks that are missing into
``~/ros2-course/notebooks/`` and gives the learner the ROS workspace
``~/ros2-course/workspace/ROS2_and_RL_Tutorials``.

The hand-in service (``ros2nb_instructor.hub.hand_in_service``, a managed service at
``/services/hand-in/``, run by the hub as root) keeps what each learner hands in with
``ros2nb.hand_in("03")`` and the time by its own clock, in the store
``<state>/handed-in/`` that only root can read or change; it shows each learner their own
feedback once ``make hub-feedback`` released it.  Learners' tokens and logins may reach it
(``access:services!service=hand-in``); each learner's server is told its address.

Settings come from the environment (``make hub VARIABLE=value`` sets them too):

==========================  =====================  ==========================================
variable                    default                meaning
==========================  =====================  ==========================================
ROS2_COURSE_HUB_IP          127.0.0.1              address the hub (its proxy) listens on
ROS2_COURSE_HUB_PORT        8000                   port the learners open in the browser
ROS2_COURSE_HUB_GROUP       ros2-course            Unix group whose members may log in
ROS2_COURSE_HUB_ADMINS      (nobody)               instructors' user names, space-separated
ROS2_COURSE_HUB_STATE       <course>/.cache/hub    database, cookie secret, proxy pid file
ROS2_COURSE_HUB_HANDED_IN   <state>/handed-in      the hand-in store (root's alone)
ROS2_COURSE_HUB_HAND_IN_PORT 8090                  the hand-in service's port on 127.0.0.1
==========================  =====================  ==========================================

The hub's own API listens on 127.0.0.1:8081 and the proxy's API on 127.0.0.1:8001; the
learners' servers get free ports on 127.0.0.1. ``ROS_DOMAIN_ID`` is never passed on to the
learners' servers: with it unset, ``ros2nb.start()`` picks a free ROS domain for each kernel,
so two learners never share one.
"""

import os
import sys
from pathlib import Path

c = get_config()  # noqa: F821 -- JupyterHub defines get_config() for its config files

#: The course repository (this file is environment/jupyterhub_config.py inside it).
COURSE = Path(__file__).resolve().parent.parent
#: The course's venv interpreter; every learner's server and kernel run on it.
COURSE_PYTHON = COURSE / '.venv' / 'bin' / 'python'
#: configurable-http-proxy as the Makefile installs it (`make hub-proxy`).
PROXY = COURSE / '.cache' / 'node' / 'node_modules' / '.bin' / 'configurable-http-proxy'
#: Each learner's course folder, inside their home.
LEARNER_FOLDER = '~/ros2-course'
#: A kernel idle this long is shut down (s): its memory goes back to the class.
KERNEL_IDLE_TIMEOUT_S = 2 * 60 * 60
#: Seconds a learner's server may take to start (the first ROS import is slow).
START_TIMEOUT_S = 90
#: Only these variables of the hub's environment reach the learners' servers. ROS_DOMAIN_ID
#: is left out on purpose, so that two learners never share a ROS domain.
KEPT_VARIABLES = ['PATH', 'LANG', 'LC_ALL', 'JUPYTERHUB_SINGLEUSER_APP']
#: The hand-in service's name (its address is /services/hand-in/).
HAND_IN = 'hand-in'
#: What a learner's server token may do: the hub's default for a server, and hand in.
SERVER_TOKEN_SCOPES = ['users:activity!user', 'access:servers!server',
                       f'access:services!service={HAND_IN}']


def setting(name: str, default: str) -> str:
    """Return the environment variable ``ROS2_COURSE_HUB_<name>`` or ``default``."""
    return os.environ.get(f'ROS2_COURSE_HUB_{name}', default)


def state_folder() -> Path:
    """Create the folder of the hub's database and secrets, readable by root only."""
    folder = Path(setting('STATE', str(COURSE / '.cache' / 'hub'))).resolve()
    folder.mkdir(mode=0o700, parents=True, exist_ok=True)
    folder.chmod(0o700)
    return folder


for required, fix in ((COURSE_PYTHON, 'make setup'), (PROXY, 'make hub-proxy')):
    if not required.exists():
        sys.exit(f'{required} is missing: run `{fix}` in {COURSE}, then start the hub again.')

STATE = state_folder()
HAND_IN_URL = f"http://127.0.0.1:{setting('HAND_IN_PORT', '8090')}"
HANDED_IN = Path(setting('HANDED_IN', str(STATE / 'handed-in'))).resolve()

# --- who may log in: Unix users of one group, passwords checked by PAM
c.JupyterHub.authenticator_class = 'pam'
c.PAMAuthenticator.allowed_groups = {setting('GROUP', 'ros2-course')}
c.Authenticator.admin_users = set(setting('ADMINS', '').split())

# --- where it listens, where it keeps its state
c.JupyterHub.bind_url = f"http://{setting('IP', '127.0.0.1')}:{setting('PORT', '8000')}"
c.JupyterHub.hub_bind_url = 'http://127.0.0.1:8081'
c.ConfigurableHTTPProxy.api_url = 'http://127.0.0.1:8001'
c.ConfigurableHTTPProxy.command = [str(PROXY)]
c.ConfigurableHTTPProxy.pid_file = str(STATE / 'proxy.pid')
c.JupyterHub.db_url = f'sqlite:///{STATE / "jupyterhub.sqlite"}'
c.JupyterHub.cookie_secret_file = str(STATE / 'jupyterhub_cookie_secret')

# --- each learner's server: their own Unix user, the course's venv, their own course folder
c.JupyterHub.spawner_class = 'localprocess'
c.Spawner.cmd = [str(COURSE_PYTHON), '-m', 'ros2nb_instructor.hub.singleuser']
c.Spawner.notebook_dir = LEARNER_FOLDER
c.Spawner.default_url = '/lab/tree/notebooks'
c.Spawner.env_keep = KEPT_VARIABLES
# OPENBLAS_NUM_THREADS: numpy's BLAS threads spin at import in every ROS process (rclpy's message
# types import numpy), on cores the whole class shares; the course does no linear algebra.
c.Spawner.environment = {'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST', 'OPENBLAS_NUM_THREADS': '1',
                         'ROS2NB_HAND_IN_URL': f'{HAND_IN_URL}/services/{HAND_IN}/'}
c.Spawner.args = [f'--MappingKernelManager.cull_idle_timeout={KERNEL_IDLE_TIMEOUT_S}',
                  '--MappingKernelManager.cull_interval=300']
c.Spawner.start_timeout = START_TIMEOUT_S
c.Spawner.http_timeout = START_TIMEOUT_S

# --- the hand-in service: each hand-in kept with the time by its clock, where learners cannot
# write; learners' logins and their servers' tokens may reach it (and nothing else of it)
c.JupyterHub.services = [{
    'name': HAND_IN, 'url': HAND_IN_URL, 'oauth_no_confirm': True,
    'command': [str(COURSE_PYTHON), '-m', 'ros2nb_instructor.hub.hand_in_service',
                '--store', str(HANDED_IN), '--settings', str(COURSE / 'course.toml')]}]
c.JupyterHub.extra_user_scopes = {f'access:services!service={HAND_IN}'}
c.Spawner.server_token_scopes = SERVER_TOKEN_SCOPES

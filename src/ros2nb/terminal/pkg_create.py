"""``ros2 pkg create --build-type ament_python``, reproduced in the kernel.

Introduced in ``02-create-a-package.ipynb``.

There is no ``ros2`` command line in the course environment, so :func:`pkg_create`
does what ROS 2 Jazzy's ``ros2 pkg create --build-type ament_python NAME
--dependencies DEP ...`` does: it prints the same lines, creates the same folders
and writes the same files, byte for byte.

The file contents mirror the empy templates of the ``ros2pkg`` package of ROS 2
Jazzy (repository https://github.com/ros2/ros2cli, branch ``jazzy``):

* ``ros2pkg/ros2pkg/resource/package_environment/package.xml.em``
* ``ros2pkg/ros2pkg/resource/ament_python/setup.py.em``, ``setup.cfg.em``,
  ``resource_file.em`` (empty), ``init.py.em`` (empty), ``main.py.em``,
  ``test_copyright.py.em``, ``test_flake8.py.em`` and ``test_pep257.py.em``

and the printed lines, defaults and refusals mirror ``ros2pkg/ros2pkg/verb/create.py``
and ``ros2pkg/ros2pkg/api/create.py`` of the same branch.  Only the template text
is taken over, exactly, because identical output is the point; the code around it
is this module's own and renders the templates without empy.  The ``setup.py`` is
the one Jazzy writes since ros2cli 0.32.6 (``extras_require={'test': ['pytest']}``;
0.32.0 to 0.32.5 wrote ``tests_require=['pytest']`` there instead).

What differs from the command line, on purpose:

* only ``build_type='ament_python'`` is supported;
* a package name that breaks REP 144 is refused (``ros2 pkg create`` accepts it);
* a license that ``ament_copyright`` knows (``Apache-2.0``, ``MIT``, ...) is refused,
  because the real command then also writes a ``LICENSE`` file with the full license
  text, which this module does not carry; ``'?'`` (list the licenses) is refused too.
"""

from __future__ import annotations

import getpass
import os
import pathlib
import re
import shutil
import subprocess
from collections.abc import Sequence

from ..errors import PkgCreateError
from .files import remember_written
from .pkg_templates import (SETUP_CFG, TEST_COPYRIGHT_PY, TEST_FLAKE8_PY, TEST_PEP257_PY,
                            AMENT_PYTHON_TEST_DEPENDENCIES, render_main_py, render_package_xml,
                            render_setup_py)

__all__ = [
    'AMENT_LICENSE_IDENTIFIERS', 'AMENT_PYTHON_TEST_DEPENDENCIES',
    'EXPECTED_FILES_AMENT_PYTHON', 'PkgCreateError', 'expected_files', 'pkg_create',
]

#: Build types ``ros2 pkg create --build-type`` accepts on Jazzy.
CLI_BUILD_TYPES = ('cmake', 'ament_cmake', 'ament_cargo', 'ament_python')
#: Build types :func:`pkg_create` reproduces.
SUPPORTED_BUILD_TYPES = ('ament_python',)
#: SPDX identifiers that Jazzy's ``ament_copyright`` ships license texts for, in the
#: order ``ros2 pkg create`` lists them (its entry points, sorted by name).
AMENT_LICENSE_IDENTIFIERS = (
    'Apache-2.0', 'BSL-1.0', 'BSD-2.0', 'BSD-2-Clause', 'BSD-3-Clause', 'GPL-3.0-only',
    'LGPL-3.0-only', 'MIT', 'MIT-0')
#: Files (not folders) the real command creates for an ament_python package without
#: ``--node-name``, relative to the package folder, in creation order; fill in
#: ``{package_name}`` with :meth:`str.format` or use :func:`expected_files`.
EXPECTED_FILES_AMENT_PYTHON: tuple[str, ...] = (
    'package.xml',
    'setup.py',
    'setup.cfg',
    'resource/{package_name}',
    '{package_name}/__init__.py',
    'test/test_copyright.py',
    'test/test_flake8.py',
    'test/test_pep257.py',
)

#: REP 144: lowercase letters, digits and underscores, starting with a letter.
_PACKAGE_NAME = re.compile(r'[a-z][a-z0-9_]*')


def expected_files(package_name: str, node_name: str | None = None) -> list[str]:
    """Return the files :func:`pkg_create` creates, relative to the package folder.

    Introduced in ``02-create-a-package.ipynb``.

    :param package_name: the package's name.
    :param node_name: the ``node_name`` passed to :func:`pkg_create`, if any.
    :return: POSIX-style relative paths in creation order (folders are not listed).
    """
    files = [path.format(package_name=package_name) for path in EXPECTED_FILES_AMENT_PYTHON]
    if node_name:
        files.append(f'{package_name}/{node_name}.py')
    return files


def _git_config_email() -> str:
    """Return ``git config user.email`` as ros2pkg reads it, or '' without git or a value."""
    git = shutil.which('git')
    if git is None:
        return ''
    completed = subprocess.run([git, 'config', 'user.email'], stdout=subprocess.PIPE)
    return completed.stdout.decode().rstrip()


def _check_request(package_name: str, build_type: str, license: str,
                   package_path: str) -> None:
    """Raise :class:`PkgCreateError` for every request the real command (or we) refuse."""
    if build_type not in SUPPORTED_BUILD_TYPES:
        raise PkgCreateError(
            f"pkg_create supports only build_type='ament_python', not {build_type!r}; "
            f"ros2 pkg create itself offers {', '.join(CLI_BUILD_TYPES)}")
    if not _PACKAGE_NAME.fullmatch(package_name):
        raise PkgCreateError(
            f'Invalid package name {package_name!r}: REP 144 package names use only '
            'lowercase letters, digits and underscores and start with a letter')
    if license == '?':
        raise PkgCreateError(
            "license='?' only lists licenses in ros2 pkg create; the ament license "
            f"identifiers are: {', '.join(AMENT_LICENSE_IDENTIFIERS)}")
    if license in AMENT_LICENSE_IDENTIFIERS:
        raise PkgCreateError(
            f'license {license!r} makes ros2 pkg create also write a LICENSE file with the '
            'full license text, which pkg_create does not reproduce; pass another license '
            'string')
    # The command line's own refusals, word for word and in its order.
    if package_name == 'test':
        raise PkgCreateError(
            "Aborted since 'ament_python' packages can't be named 'test'. Please "
            'choose a different package name.')
    if os.path.exists(package_path):
        raise PkgCreateError(
            '\nAborted!\nThe directory already exists: ' + package_path + '\nEither '
            'remove the directory or choose a different destination directory or package name')


def pkg_create(package_name: str, *, destination: str | os.PathLike[str] = '.',
               build_type: str = 'ament_python', dependencies: Sequence[str] = (),
               description: str = 'TODO: Package description',
               license: str = 'TODO: License declaration',
               maintainer_name: str | None = None,
               maintainer_email: str | None = None,
               node_name: str | None = None) -> pathlib.Path:
    """Create an ament_python package, like ``ros2 pkg create --build-type ament_python``.

    Introduced in ``02-create-a-package.ipynb``.

    When a real ``ros2`` is on PATH it runs ``ros2 pkg create`` with the same options.
    Otherwise it prints what the command prints and writes exactly the files it writes, with the
    same contents, for the same arguments.  The checks all run before anything is
    created, so a refused call never touches the file system, and an existing package
    folder is never modified.

    Defaults follow the command: the login name, and ``git config user.email`` (else
    ``<name>@todo.todo``) as the maintainer's email.

    :param package_name: the package's name (``ros2 pkg create NAME``).
    :param destination: folder to create the package folder in
        (``--destination-directory``); created if missing.
    :param build_type: ``--build-type``; only ``'ament_python'`` is supported.
    :param dependencies: ``--dependencies``, written as ``<depend>`` in this order.
    :param description: ``--description``, written unescaped as the command does.
    :param license: ``--license``; any string except the SPDX identifiers in
        :data:`AMENT_LICENSE_IDENTIFIERS` and ``'?'``.
    :param maintainer_name: ``--maintainer-name``; ``None`` means the login name.
    :param maintainer_email: ``--maintainer-email``; ``None`` or ``''`` means the git
        email, then ``<maintainer_name>@todo.todo``.
    :param node_name: ``--node-name``: also create ``NAME/NODE.py`` and its
        ``console_scripts`` entry.
    :return: the new package folder (``destination / package_name``).
    :raises PkgCreateError: if the package folder already exists, the name is ``test``
        or breaks REP 144, the build type is not ament_python, or the license is one
        whose LICENSE file this module cannot write; the message is the text
        ``ros2 pkg create`` prints where it has one.
    :raises TypeError: if ``dependencies`` is a single string instead of a list.
    """
    dependencies = _dependency_list(dependencies)
    destination_directory = os.fspath(destination)
    package_path = os.path.join(destination_directory, package_name)
    _check_request(package_name, build_type, license, package_path)
    maintainer_name, maintainer_email = _maintainer(maintainer_name, maintainer_email)
    maintainer = f'{maintainer_name} <{maintainer_email}>'
    real_ros2 = shutil.which('ros2')
    if real_ros2:  # a real ROS 2 install: let its CLI do the work
        _run_real_ros2(real_ros2, package_name, destination_directory, build_type, description,
                       license, maintainer_name, maintainer_email, dependencies, node_name)
        return pathlib.Path(package_path)
    _print_request(package_name, destination_directory, description, maintainer, license,
                   build_type, dependencies, node_name)
    _write_package(package_name, destination_directory, description, maintainer_name,
                   maintainer_email, license, dependencies, node_name)
    print("\n[WARNING]: Unknown license '%s'.  This has been set in the package.xml, but "
          'no LICENSE file has been created.\nIt is recommended to use one of the ament '
          'license identifiers:\n%s' % (license, '\n'.join(AMENT_LICENSE_IDENTIFIERS)))
    return pathlib.Path(package_path)


def _dependency_list(dependencies: Sequence[str]) -> list[str]:
    """``--dependencies`` as a list of names.

    :raises TypeError: for a single string (a common slip: ``'rclpy'`` for ``['rclpy']``).
    """
    if isinstance(dependencies, str):
        raise TypeError(f'dependencies must be a list of package names, e.g. '
                        f'[{dependencies!r}], not the string {dependencies!r}')
    return [str(dependency) for dependency in dependencies]


def _maintainer(name: str | None, email: str | None) -> tuple[str, str]:
    """The command's defaults: the login name, then git's email or ``<name>@todo.todo``."""
    if name is None:
        name = getpass.getuser()
    if not email:
        email = _git_config_email() or name + '@todo.todo'
    return name, email


def _run_real_ros2(ros2: str, package_name: str, destination_directory: str, build_type: str,
                   description: str, license: str, maintainer_name: str, maintainer_email: str,
                   dependencies: Sequence[str], node_name: str | None) -> None:
    """``ros2 pkg create`` itself, with the same options; its output shown here."""
    argv = [ros2, 'pkg', 'create', '--build-type', build_type,
            '--destination-directory', destination_directory,
            '--description', description, '--license', license,
            '--maintainer-name', maintainer_name, '--maintainer-email', maintainer_email]
    if dependencies:
        argv += ['--dependencies', *dependencies]
    if node_name:
        argv += ['--node-name', node_name]
    done = subprocess.run(argv + [package_name], capture_output=True, text=True)
    print(done.stdout, end='')
    if done.returncode != 0:
        raise PkgCreateError((done.stderr.strip() or done.stdout.strip()).splitlines()[-1])


def _print_request(package_name: str, destination_directory: str, description: str,
                   maintainer: str, license: str, build_type: str,
                   dependencies: Sequence[str], node_name: str | None) -> None:
    """The lines ``ros2 pkg create`` prints before it creates anything."""
    print('going to create a new package')
    print('package name:', package_name)
    print('destination directory:', os.path.abspath(destination_directory))
    print('package format:', 3)
    print('version:', '0.0.0')
    print('description:', description)
    print('maintainer:', [maintainer])
    print('licenses:', [license])
    print('build type:', build_type)
    print('dependencies:', list(dependencies))
    if node_name:
        print('node_name:', node_name)


def _create_folder(folder_name: str, base_directory: str) -> str:
    folder_path = os.path.join(base_directory, folder_name)
    print('creating folder', folder_path)
    os.makedirs(folder_path, exist_ok=True)
    return folder_path


def _create_file(output_directory: str, output_file_name: str, content: str) -> None:
    output_file_path = os.path.join(output_directory, output_file_name)
    print('creating', output_file_path)
    with open(output_file_path, 'w', encoding='utf-8', newline='\n') as stream:
        stream.write(content)
    # ros2nb may later update this file for you (e.g. setup.py in notebook 05),
    # but only while you have not edited it yourself.
    remember_written(output_file_path)


def _write_package(package_name: str, destination_directory: str, description: str,
                   maintainer_name: str, maintainer_email: str, license: str,
                   dependencies: Sequence[str], node_name: str | None) -> None:
    """The folders and files, in the command's order (its create_package_environment,
    populate_ament_python and populate_python_node)."""
    package_directory = _create_folder(package_name, destination_directory)
    _create_file(package_directory, 'package.xml', render_package_xml(
        package_name, description, maintainer_name, maintainer_email, license,
        dependencies))
    print('creating source folder')
    source_directory = _create_folder(package_name, package_directory)
    _create_file(package_directory, 'setup.py', render_setup_py(
        package_name, description, maintainer_name, maintainer_email, license, node_name))
    _create_file(package_directory, 'setup.cfg', SETUP_CFG.format(name=package_name))
    resource_directory = _create_folder('resource', package_directory)
    _create_file(resource_directory, package_name, '')
    _create_file(source_directory, '__init__.py', '')
    test_directory = _create_folder('test', package_directory)
    _create_file(test_directory, 'test_copyright.py', TEST_COPYRIGHT_PY)
    _create_file(test_directory, 'test_flake8.py', TEST_FLAKE8_PY)
    _create_file(test_directory, 'test_pep257.py', TEST_PEP257_PY)
    if node_name:
        _create_file(source_directory, node_name + '.py', render_main_py(package_name))

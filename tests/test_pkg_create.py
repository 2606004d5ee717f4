"""Tests for ros2nb.terminal.pkg_create: the files and output of Jazzy's ``ros2 pkg create``."""

from __future__ import annotations

import ast
import getpass
import os
import pathlib
import shutil
import xml.etree.ElementTree as ET

import pytest

from ros2nb.terminal.pkg_create import (AMENT_PYTHON_TEST_DEPENDENCIES, EXPECTED_FILES_AMENT_PYTHON,
                               PkgCreateError, expected_files, pkg_create)

NAME = 'sensor_simulator'
DEPS = ['rclpy', 'std_msgs']
MAINTAINER = {'maintainer_name': 'Ada', 'maintainer_email': 'ada@example.com'}

# What Jazzy's ros2 pkg create writes for these arguments (rendered templates).
EXPECTED_PACKAGE_XML = '''\
<?xml version="1.0"?>
<?xml-model href="http://download.ros.org/schema/package_format3.xsd" \
schematypens="http://www.w3.org/2001/XMLSchema"?>
<package format="3">
  <name>sensor_simulator</name>
  <version>0.0.0</version>
  <description>TODO: Package description</description>
  <maintainer email="ada@example.com">Ada</maintainer>
  <license>TODO: License declaration</license>

  <depend>rclpy</depend>
  <depend>std_msgs</depend>

  <test_depend>ament_copyright</test_depend>
  <test_depend>ament_flake8</test_depend>
  <test_depend>ament_pep257</test_depend>
  <test_depend>python3-pytest</test_depend>

  <export>
    <build_type>ament_python</build_type>
  </export>
</package>
'''

EXPECTED_SETUP_CFG = '''\
[develop]
script_dir=$base/lib/sensor_simulator
[install]
install_scripts=$base/lib/sensor_simulator
'''

EXPECTED_OUTPUT = '''\
going to create a new package
package name: sensor_simulator
destination directory: {destination}
package format: 3
version: 0.0.0
description: TODO: Package description
maintainer: ['Ada <ada@example.com>']
licenses: ['TODO: License declaration']
build type: ament_python
dependencies: ['rclpy', 'std_msgs']
creating folder ./sensor_simulator
creating ./sensor_simulator/package.xml
creating source folder
creating folder ./sensor_simulator/sensor_simulator
creating ./sensor_simulator/setup.py
creating ./sensor_simulator/setup.cfg
creating folder ./sensor_simulator/resource
creating ./sensor_simulator/resource/sensor_simulator
creating ./sensor_simulator/sensor_simulator/__init__.py
creating folder ./sensor_simulator/test
creating ./sensor_simulator/test/test_copyright.py
creating ./sensor_simulator/test/test_flake8.py
creating ./sensor_simulator/test/test_pep257.py

[WARNING]: Unknown license 'TODO: License declaration'.  This has been set in the \
package.xml, but no LICENSE file has been created.
It is recommended to use one of the ament license identifiers:
Apache-2.0
BSL-1.0
BSD-2.0
BSD-2-Clause
BSD-3-Clause
GPL-3.0-only
LGPL-3.0-only
MIT
MIT-0
'''


def _files(root: pathlib.Path) -> set[str]:
    return {path.relative_to(root).as_posix() for path in root.rglob('*') if path.is_file()}


def _snapshot(root: pathlib.Path) -> dict[str, bytes]:
    return {path.relative_to(root).as_posix(): path.read_bytes()
            for path in root.rglob('*') if path.is_file()}


@pytest.fixture
def package(tmp_path: pathlib.Path) -> pathlib.Path:
    return pkg_create(NAME, destination=tmp_path, dependencies=DEPS, **MAINTAINER)


def test_file_list(tmp_path: pathlib.Path, package: pathlib.Path) -> None:
    assert package == tmp_path / NAME
    assert expected_files(NAME) == [p.format(package_name=NAME)
                                    for p in EXPECTED_FILES_AMENT_PYTHON]
    assert _files(package) == set(expected_files(NAME))
    assert sorted(p.name for p in package.iterdir()) == sorted(
        ['package.xml', 'setup.py', 'setup.cfg', 'resource', NAME, 'test'])


def test_package_xml(package: pathlib.Path) -> None:
    text = (package / 'package.xml').read_text()
    assert text == EXPECTED_PACKAGE_XML
    root = ET.fromstring(text)
    assert root.tag == 'package' and root.get('format') == '3'
    assert root.findtext('name') == NAME
    assert root.findtext('version') == '0.0.0'
    assert [e.text for e in root.findall('depend')] == DEPS
    assert [e.text for e in root.findall('test_depend')] == [
        'ament_copyright', 'ament_flake8', 'ament_pep257', 'python3-pytest']
    assert list(AMENT_PYTHON_TEST_DEPENDENCIES) == [e.text for e in root.findall('test_depend')]
    assert root.findall('buildtool_depend') == []
    assert root.find('export/build_type').text == 'ament_python'
    maintainer = root.find('maintainer')
    assert (maintainer.text, maintainer.get('email')) == ('Ada', 'ada@example.com')


def test_package_xml_without_dependencies(tmp_path: pathlib.Path) -> None:
    package = pkg_create('bare', destination=tmp_path, **MAINTAINER)
    text = (package / 'package.xml').read_text()
    assert '<depend>' not in text
    assert ('  <license>TODO: License declaration</license>\n\n'
            '  <test_depend>ament_copyright</test_depend>\n') in text


def test_setup_cfg(package: pathlib.Path) -> None:
    assert (package / 'setup.cfg').read_text() == EXPECTED_SETUP_CFG


def _setup_call(source: str) -> ast.Call:
    tree = ast.parse(source)
    calls = [node for node in ast.walk(tree)
             if isinstance(node, ast.Call) and getattr(node.func, 'id', None) == 'setup']
    assert len(calls) == 1
    return calls[0]


def test_setup_py(package: pathlib.Path) -> None:
    source = (package / 'setup.py').read_text()
    compile(source, 'setup.py', 'exec')
    assert source.startswith('from setuptools import find_packages, setup\n')
    assert f"package_name = '{NAME}'" in source
    assert "packages=find_packages(exclude=['test'])," in source
    assert ("        ('share/ament_index/resource_index/packages',\n"
            "            ['resource/' + package_name]),\n") in source
    assert "('share/' + package_name, ['package.xml'])," in source
    keywords = {k.arg: k.value for k in _setup_call(source).keywords}
    assert ast.literal_eval(keywords['entry_points']) == {'console_scripts': []}
    assert ast.literal_eval(keywords['maintainer']) == 'Ada'
    assert ast.literal_eval(keywords['maintainer_email']) == 'ada@example.com'
    assert ast.literal_eval(keywords['install_requires']) == ['setuptools']
    assert ast.literal_eval(keywords['extras_require']) == {'test': ['pytest']}


def test_resource_marker_and_init_are_empty(package: pathlib.Path) -> None:
    marker = package / 'resource' / NAME
    assert marker.is_file() and marker.read_bytes() == b''
    assert (package / NAME / '__init__.py').read_bytes() == b''


def test_linter_tests_are_valid_python(package: pathlib.Path) -> None:
    for name in ('test_copyright.py', 'test_flake8.py', 'test_pep257.py'):
        source = (package / 'test' / name).read_text()
        compile(source, name, 'exec')
        assert source.startswith('# Copyright 20')
    assert "@pytest.mark.skip(reason='No copyright header has been placed in the generated " \
        "source file.')" in (package / 'test' / 'test_copyright.py').read_text()


def test_node_name(tmp_path: pathlib.Path, capsys: pytest.CaptureFixture[str]) -> None:
    package = pkg_create(NAME, destination=tmp_path, node_name='simulator', **MAINTAINER)
    assert _files(package) == set(expected_files(NAME, node_name='simulator'))
    node = (package / NAME / 'simulator.py').read_text()
    assert node == ("def main():\n    print('Hi from sensor_simulator.')\n\n\n"
                    "if __name__ == '__main__':\n    main()\n")
    keywords = {k.arg: k.value for k in _setup_call((package / 'setup.py').read_text()).keywords}
    assert ast.literal_eval(keywords['entry_points']) == {
        'console_scripts': ['simulator = sensor_simulator.simulator:main']}
    out = capsys.readouterr().out.splitlines()
    assert out[out.index("dependencies: []") + 1] == 'node_name: simulator'
    assert out[out.index(f'creating {tmp_path}/{NAME}/test/test_pep257.py') + 1] == \
        f'creating {tmp_path}/{NAME}/{NAME}/simulator.py'


def test_printed_output(tmp_path: pathlib.Path, monkeypatch: pytest.MonkeyPatch,
                        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(tmp_path)
    package = pkg_create(NAME, dependencies=DEPS, **MAINTAINER)
    assert package == pathlib.Path('.', NAME)
    assert capsys.readouterr().out == EXPECTED_OUTPUT.format(destination=os.getcwd())


def test_existing_directory_is_refused_and_untouched(tmp_path: pathlib.Path,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    existing = tmp_path / NAME
    existing.mkdir()
    (existing / 'sentinel.txt').write_text('keep me\n')
    before = _snapshot(existing)
    with pytest.raises(PkgCreateError) as error:
        pkg_create(NAME, destination=tmp_path, dependencies=DEPS, **MAINTAINER)
    assert str(error.value) == (
        f'\nAborted!\nThe directory already exists: {tmp_path}/{NAME}\nEither remove the '
        'directory or choose a different destination directory or package name')
    assert _snapshot(existing) == before
    assert sorted(p.name for p in existing.iterdir()) == ['sentinel.txt']
    assert capsys.readouterr().out == ''


def test_name_test_is_refused(tmp_path: pathlib.Path) -> None:
    with pytest.raises(PkgCreateError) as error:
        pkg_create('test', destination=tmp_path, **MAINTAINER)
    assert str(error.value) == ("Aborted since 'ament_python' packages can't be named 'test'. "
                                'Please choose a different package name.')
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize('bad_name', ['SensorSimulator', 'sensor-simulator', '1sensor',
                                      '_sensor', 'sensor simulator', ''])
def test_bad_name_is_refused(tmp_path: pathlib.Path, bad_name: str) -> None:
    with pytest.raises(PkgCreateError, match='REP 144') as error:
        pkg_create(bad_name, destination=tmp_path, **MAINTAINER)
    assert '\n' not in str(error.value)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize('build_type', ['ament_cmake', 'cmake', 'ament_cargo', 'python'])
def test_other_build_types_are_refused(tmp_path: pathlib.Path, build_type: str) -> None:
    with pytest.raises(PkgCreateError, match="only build_type='ament_python'"):
        pkg_create(NAME, destination=tmp_path, build_type=build_type, **MAINTAINER)
    assert list(tmp_path.iterdir()) == []


def test_licenses_with_a_license_file_are_refused(tmp_path: pathlib.Path) -> None:
    with pytest.raises(PkgCreateError, match='LICENSE file'):
        pkg_create(NAME, destination=tmp_path, license='Apache-2.0', **MAINTAINER)
    assert list(tmp_path.iterdir()) == []


def test_other_license_string_is_written(tmp_path: pathlib.Path) -> None:
    package = pkg_create(NAME, destination=tmp_path, license='Proprietary', **MAINTAINER)
    assert '<license>Proprietary</license>' in (package / 'package.xml').read_text()
    assert "    license='Proprietary',\n" in (package / 'setup.py').read_text()


def test_dependencies_as_one_string_is_a_type_error(tmp_path: pathlib.Path) -> None:
    with pytest.raises(TypeError, match=r"\['rclpy'\]"):
        pkg_create(NAME, destination=tmp_path, dependencies='rclpy', **MAINTAINER)
    assert list(tmp_path.iterdir()) == []


def test_missing_destination_is_created(tmp_path: pathlib.Path) -> None:
    package = pkg_create(NAME, destination=tmp_path / 'ws' / 'src', **MAINTAINER)
    assert (package / 'package.xml').is_file()


@pytest.mark.skipif(shutil.which('git') is None, reason='git is not installed')
def test_maintainer_defaults_follow_git_then_login(tmp_path: pathlib.Path,
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    work = tmp_path / 'work'
    work.mkdir()
    monkeypatch.chdir(work)  # not inside a git repository: only the global file counts
    gitconfig = tmp_path / 'gitconfig'
    monkeypatch.setenv('GIT_CONFIG_GLOBAL', str(gitconfig))
    monkeypatch.setenv('GIT_CONFIG_NOSYSTEM', '1')
    monkeypatch.delenv('GIT_CONFIG', raising=False)

    gitconfig.write_text('[user]\n\temail = learner@example.org\n')
    root = ET.parse(pkg_create('from_git') / 'package.xml').getroot()
    assert root.find('maintainer').get('email') == 'learner@example.org'
    assert root.findtext('maintainer') == getpass.getuser()

    gitconfig.write_text('')
    root = ET.parse(pkg_create('no_git_email') / 'package.xml').getroot()
    assert root.find('maintainer').get('email') == getpass.getuser() + '@todo.todo'

    root = ET.parse(pkg_create('named', maintainer_name='Grace') / 'package.xml').getroot()
    assert (root.findtext('maintainer'), root.find('maintainer').get('email')) == (
        'Grace', 'Grace@todo.todo')


def test_defers_to_a_real_ros2_on_path(tmp_path, monkeypatch):
    """With a `ros2` on PATH the real CLI is called (a recording stand-in checks the call)."""
    bin_dir = tmp_path / 'bin'
    bin_dir.mkdir()
    calls = tmp_path / 'calls.txt'
    stub = bin_dir / 'ros2'
    stub.write_text(f'#!/bin/sh\necho "$@" >> {calls}\necho created by the real CLI\n')
    stub.chmod(0o755)
    monkeypatch.setenv('PATH', f'{bin_dir}{os.pathsep}{os.environ["PATH"]}')
    pkg_create('sensor_simulator', destination=tmp_path, dependencies=['rclpy', 'std_msgs'],
               maintainer_name='learner', maintainer_email='learner@example.com')
    argv = calls.read_text().split()
    assert argv[:4] == ['pkg', 'create', '--build-type', 'ament_python']
    assert argv[-4:] == ['--dependencies', 'rclpy', 'std_msgs', 'sensor_simulator']
    assert not (tmp_path / 'sensor_simulator').exists()  # ros2nb wrote nothing itself

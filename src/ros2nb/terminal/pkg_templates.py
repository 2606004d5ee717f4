"""The files ``ros2 pkg create --build-type ament_python`` writes, as Jazzy's templates render them.

Used by :mod:`ros2nb.terminal.pkg_create`.  The text is ros2pkg's (repository
https://github.com/ros2/ros2cli, branch ``jazzy``, ``ros2pkg/ros2pkg/resource``): identical
output is the point; the code that renders it without empy is the course's own.
"""

from __future__ import annotations

from collections.abc import Sequence

#: ``<test_depend>`` entries the real command writes for ament_python, in its order.
AMENT_PYTHON_TEST_DEPENDENCIES = (
    'ament_copyright', 'ament_flake8', 'ament_pep257', 'python3-pytest')

# Fixed template texts, as Jazzy's empy templates render them ('@@' is empy's '@').
SETUP_CFG = (
    '[develop]\n'
    'script_dir=$base/lib/{name}\n'
    '[install]\n'
    'install_scripts=$base/lib/{name}\n'
)

TEST_COPYRIGHT_PY = '''\
# Copyright 2015 Open Source Robotics Foundation, Inc.
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

from ament_copyright.main import main
import pytest


# Remove the `skip` decorator once the source file(s) have a copyright header
@pytest.mark.skip(reason='No copyright header has been placed in the generated source file.')
@pytest.mark.copyright
@pytest.mark.linter
def test_copyright():
    rc = main(argv=['.', 'test'])
    assert rc == 0, 'Found errors'
'''

TEST_FLAKE8_PY = '''\
# Copyright 2017 Open Source Robotics Foundation, Inc.
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

from ament_flake8.main import main_with_errors
import pytest


@pytest.mark.flake8
@pytest.mark.linter
def test_flake8():
    rc, errors = main_with_errors(argv=[])
    assert rc == 0, \\
        'Found %d code style errors / warnings:\\n' % len(errors) + \\
        '\\n'.join(errors)
'''

TEST_PEP257_PY = '''\
# Copyright 2015 Open Source Robotics Foundation, Inc.
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

from ament_pep257.main import main
import pytest


@pytest.mark.linter
@pytest.mark.pep257
def test_pep257():
    rc = main(argv=['.', 'test'])
    assert rc == 0, 'Found code style errors / warnings'
'''


def render_package_xml(name: str, description: str, maintainer_name: str,
                        maintainer_email: str, license: str,
                        dependencies: Sequence[str]) -> str:
    """Render ``package_environment/package.xml.em`` for an ament_python package."""
    text = (
        '<?xml version="1.0"?>\n'
        '<?xml-model href="http://download.ros.org/schema/package_format3.xsd" '
        'schematypens="http://www.w3.org/2001/XMLSchema"?>\n'
        '<package format="3">\n'
        f'  <name>{name}</name>\n'
        '  <version>0.0.0</version>\n'
        f'  <description>{description}</description>\n'
        f'  <maintainer email="{maintainer_email}">{maintainer_name}</maintainer>\n'
        f'  <license>{license}</license>\n'
        '\n'
    )
    # ament_python has no <buildtool_depend>; each non-empty group ends with a blank line.
    if dependencies:
        text += ''.join(f'  <depend>{dep}</depend>\n' for dep in dependencies) + '\n'
    text += ''.join(f'  <test_depend>{dep}</test_depend>\n'
                    for dep in AMENT_PYTHON_TEST_DEPENDENCIES) + '\n'
    text += (
        '  <export>\n'
        '    <build_type>ament_python</build_type>\n'
        '  </export>\n'
        '</package>\n'
    )
    return text


def render_setup_py(name: str, description: str, maintainer_name: str,
                     maintainer_email: str, license: str, node_name: str | None) -> str:
    """Render ``ament_python/setup.py.em``."""
    console_scripts = ''
    if node_name:
        console_scripts = f"            '{node_name} = {name}.{node_name}:main'\n"
    return (
        'from setuptools import find_packages, setup\n'
        '\n'
        f"package_name = '{name}'\n"
        '\n'
        'setup(\n'
        '    name=package_name,\n'
        "    version='0.0.0',\n"
        "    packages=find_packages(exclude=['test']),\n"
        '    data_files=[\n'
        "        ('share/ament_index/resource_index/packages',\n"
        "            ['resource/' + package_name]),\n"
        "        ('share/' + package_name, ['package.xml']),\n"
        '    ],\n'
        "    install_requires=['setuptools'],\n"
        '    zip_safe=True,\n'
        f"    maintainer='{maintainer_name}',\n"
        f"    maintainer_email='{maintainer_email}',\n"
        f"    description='{description}',\n"
        f"    license='{license}',\n"
        '    extras_require={\n'
        "        'test': [\n"
        "            'pytest',\n"
        '        ],\n'
        '    },\n'
        '    entry_points={\n'
        "        'console_scripts': [\n"
        f'{console_scripts}'
        '        ],\n'
        '    },\n'
        ')\n'
    )


def render_main_py(name: str) -> str:
    """Render ``ament_python/main.py.em`` (the ``--node-name`` executable)."""
    return (
        'def main():\n'
        f"    print('Hi from {name}.')\n"
        '\n'
        '\n'
        "if __name__ == '__main__':\n"
        '    main()\n'
    )

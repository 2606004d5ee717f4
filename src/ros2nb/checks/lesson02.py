"""Checks of notebook 02, create a package: a package.xml's ``<depend>`` entries, as
catkin_pkg reads them.

Part of :mod:`ros2nb.checks`.  The learner's reader is called in the kernel there; the
judge calls it from the learner's answer cell in a subject, also on a package.xml of its own.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

from catkin_pkg.package import InvalidPackage, parse_package, parse_package_string

from .. import course
from ..errors import CheckFailed, Ros2nbError
from ..terminal.workspace import current_workspace
from .answers import answer_results, decoded, type_name_of
from ..judge_interface import AnswerRef, Judge
from .base import call_learner, direct


def package_dependencies(package_xml: Path) -> list[str]:
    """Return the ``<depend>`` entries of a package.xml, in order, as catkin_pkg reads them.

    A ``<depend>`` is needed to build, to export and to run, so it is a name that shows up
    in all three of catkin_pkg's lists.

    Introduced in ``02-create-a-package.ipynb``.

    :raises Ros2nbError: when the file is not a valid package.xml.
    """
    try:
        package = parse_package(str(package_xml))
    except (InvalidPackage, OSError) as error:
        raise Ros2nbError(f'{package_xml} is not a valid package.xml: {error}') from None
    return _depends(package)


def _depends(package: Any) -> list[str]:
    """The ``<depend>`` entries of a catkin_pkg Package, in order."""
    exported = {d.name for d in package.build_export_depends}
    run = {d.name for d in package.exec_depends}
    return [d.name for d in package.build_depends if d.name in exported and d.name in run]


#: package.xml files the grader feeds a learner's reader, beyond the course's own.
_EXTRA_PACKAGE_XML = '''<?xml version="1.0"?>
<package format="3">
  <name>graded_reader</name>
  <version>1.2.3</version>
  <description>A package.xml of the grader's own.</description>
  <maintainer email="grader@example.com">grader</maintainer>
  <license>Apache-2.0</license>
  <buildtool_depend>ament_python</buildtool_depend>
  <depend>geometry_msgs</depend>
  <test_depend>python3-pytest</test_depend>
  <depend>  rclpy  </depend>
  <depend>sensor_msgs</depend>
  <export><build_type>ament_python</build_type></export>
</package>
'''


@direct
def check_dependencies(judge: Optional[Judge], reader: Any,
                       package_xml: Optional[Path] = None) -> str:
    """Check a learner's package.xml reader against catkin_pkg, ROS's own reader.

    Introduced in ``02-create-a-package.ipynb``.

    :param reader: the learner's function, ``reader(path) -> list[str]``.
    :param package_xml: the file to read; default the course package's in the workspace.
        The grader also feeds a package.xml of its own.
    :raises CheckFailed: when the result differs from the file's ``<depend>`` tags.
    """
    files = [Path(package_xml) if package_xml else current_workspace() / course.PACKAGE_XML_FILE]
    if not files[0].is_file():
        raise CheckFailed(f'{files[0]} does not exist: run the pkg_create cell above first.')
    # What each file declares, read before the learner's reader runs: it may write them.
    wanted = [package_dependencies(files[0])]
    # the call as the check makes it, named alike in the lab and by the grader (which sees
    # no signature of the learner's): the file it passes, whatever the parameter is called
    called = f'{reader.__name__}(package_xml)'
    if isinstance(reader, AnswerRef) and judge is not None:
        # The grader's own file: what it declares comes from its text, never from the copy
        # the learner's code can reach.
        folder = judge.hand_over('ros2nb-package-', {
            'graded_reader/package.xml': _EXTRA_PACKAGE_XML.encode()})
        files.append(folder / 'graded_reader' / 'package.xml')
        wanted.append(_depends(parse_package_string(_EXTRA_PACKAGE_XML)))
        outputs = answer_results(judge, reader, [[{'path': str(f)}] for f in files])
        results = [decoded(o, called) for o in outputs]
    else:
        results = [call_learner(reader, f, label=called) for f in files]
    for file, want, got in zip(files, wanted, results):
        if not isinstance(got, list):
            raise CheckFailed(f'{reader.__name__}() returned {type_name_of(got)}; return a list of '
                              'names.')
        odd = [type_name_of(item) for item in got if not isinstance(item, str)]
        if odd:
            raise CheckFailed(f'{reader.__name__}() returned a list of {odd[0]} objects, not of '
                              "names: return each <depend> element's text, e.g. "
                              '[element.text.strip() for element in ...].')
        if got != want:
            raise CheckFailed(f'For {file.parent.name}/package.xml you returned {got}, but it '
                              f'declares {want}: read the text of each <depend> element, in '
                              'order, without spaces around it (test_depend is not a depend).')
    return f'package.xml depends on {", ".join(wanted[0])}.'

"""The repository's license: LICENSE is the Apache License 2.0 and every package says so.

Every `package.xml` (ros_ws/src and examples/) names Apache-2.0 in `<license>`, and every
`setup.py` passes `license='Apache-2.0'`; the one exception is `tf2_msgs_fallback`, ROS 2's own
tf2_msgs message definitions, which keep their upstream BSD-3-Clause.
"""
from __future__ import annotations

import ast
import xml.etree.ElementTree as ET

from conftest import ROOT

LICENSE = 'Apache-2.0'
UPSTREAM = {'tf2_msgs_fallback': 'BSD-3-Clause'}  # a copy of another project's package
PACKAGE_DIRS = sorted(
    p.parent for pattern in ('ros_ws/src/*/package.xml', 'examples/*/package.xml')
    for p in ROOT.glob(pattern))


def _setup_license(setup_py):
    tree = ast.parse(setup_py.read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and getattr(node.func, 'id', '') == 'setup':
            for keyword in node.keywords:
                if keyword.arg == 'license':
                    return ast.literal_eval(keyword.value)
    return None


def test_license_file_is_apache_2():
    text = (ROOT / 'LICENSE').read_text()
    assert 'Apache License' in text.splitlines()[1]
    assert 'Version 2.0, January 2004' in text
    assert 'TERMS AND CONDITIONS FOR USE, REPRODUCTION, AND DISTRIBUTION' in text
    assert 'END OF TERMS AND CONDITIONS' in text


def test_every_package_xml_names_the_license():
    assert len(PACKAGE_DIRS) >= 6, PACKAGE_DIRS
    for package in PACKAGE_DIRS:
        licenses = [e.text.strip() for e in ET.parse(package / 'package.xml').iter('license')]
        assert licenses == [UPSTREAM.get(package.name, LICENSE)], (package.name, licenses)


def test_every_setup_py_names_the_license():
    setups = [p / 'setup.py' for p in PACKAGE_DIRS if (p / 'setup.py').exists()]
    assert len(setups) >= 5, setups
    for setup_py in setups:
        assert _setup_license(setup_py) == LICENSE, setup_py

"""JUnit XML for CI systems that display test results."""

from __future__ import annotations

import os
from xml.etree import ElementTree as ET

from ..atomic import atomic_output

__all__ = ["write_junit"]


def write_junit(path: str | os.PathLike, results) -> None:
    suite = ET.Element("testsuite", name="lenscompare check", tests=str(len(results)),
                       failures=str(sum(not r.passed for r in results)),
                       time=f"{sum(r.seconds for r in results):.3f}")
    for r in results:
        case = ET.SubElement(suite, "testcase", classname=f"lenscompare.{r.check.type}", name=r.check.name,
                             time=f"{r.seconds:.3f}")
        if not r.passed:
            ET.SubElement(case, "failure", message=r.message).text = r.message
        else:
            ET.SubElement(case, "system-out").text = r.message
    with atomic_output(path, option="--junit", final=True) as tmp:
        ET.ElementTree(suite).write(tmp, encoding="utf-8", xml_declaration=True)

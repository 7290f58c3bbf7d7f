"""An XDMF file read and written back keeps the ``xi`` prefix of its includes, whichever
XInclude URI the writer declared (DOLFINx 0.5.2: http, 0.9: https). A restart cuts the
displacement series this way and DOLFINx then appends steps spelled ``<xi:include>``: with
another prefix in the header the file is no longer XML (an unbound prefix)."""

import xml.etree.ElementTree as ET

import pytest

from rough_contact.io.files import parse_xdmf

STEP = ('<Grid Name="u" GridType="Uniform"><xi:include xpointer="xpointer(/Xdmf/Domain/'
        "Grid[@GridType='Uniform'][1]/*[self::Topology or self::Geometry])\" />"
        '<Time Value="1" /></Grid>')


@pytest.mark.parametrize("uri", ["http://www.w3.org/2001/XInclude",
                                 "https://www.w3.org/2001/XInclude", None])
def test_written_back_xdmf_stays_xml_when_steps_are_appended(tmp_path, uri):
    decl = "" if uri is None else f' xmlns:xi="{uri}"'
    path = tmp_path / "u.xdmf"
    path.write_text(f'<?xml version="1.0"?>\n<Xdmf Version="3.0"{decl}><Domain>'
                    f'<Grid Name="u" GridType="Collection" CollectionType="Temporal">{STEP}'
                    "</Grid></Domain></Xdmf>\n", encoding="utf-8")
    text = ET.tostring(parse_xdmf(str(path)), encoding="unicode")
    # the writer appends a step the way DOLFINx does: as text with the xi prefix
    appended = text.replace("</Grid></Domain>", STEP + "</Grid></Domain>")
    root = ET.fromstring(appended)                      # raises on an unbound prefix
    includes = [e for e in root.iter() if e.tag.endswith("}include")]
    assert len(includes) == 2

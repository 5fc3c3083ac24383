# SPDX-License-Identifier: Apache-2.0
SUMMARY = "RapidXml, a header-only DOM XML parser for C++"
DESCRIPTION = "RapidXml is an in-situ, header-only XML DOM parser. ccommd parses \
               /etc/ccomm/signals.xml with it. Neither oe-core nor meta-openembedded \
               provide it."
# nooelint: oelint.vars.homepageping - the linter runs offline
HOMEPAGE = "https://rapidxml.sourceforge.net/"
BUGTRACKER = "https://sourceforge.net/p/rapidxml/bugs/"
SECTION = "libs"
# license.txt offers the Boost Software License 1.0 or the MIT license, at the user's choice
LICENSE = "BSL-1.0 | MIT"
LIC_FILES_CHKSUM = "file://license.txt;md5=d63ab70ba21ca0544b03284958324301"

SRC_URI = "${SOURCEFORGE_MIRROR}/${BPN}/${BP}.zip"
SRC_URI[sha256sum] = "c3f0b886374981bb20fabcf323d755db4be6dba42064599481da64a85f5b3571"

UPSTREAM_CHECK_URI = "https://sourceforge.net/projects/rapidxml/files/rapidxml/"
UPSTREAM_CHECK_REGEX = "rapidxml%20(?P<pver>\d+(\.\d+)+)/"

# Header-only: nothing to configure or compile. The zip unpacks to ${BP}, which is the
# default S on every release, so S is not set.
do_configure[noexec] = "1"
do_compile[noexec] = "1"

# Debian and Gentoo install the headers the same way: <rapidxml/rapidxml.hpp>,
# which is what ccomm's CMake looks for.
do_install() {
    install -d ${D}${includedir}/rapidxml
    install -m 0644 ${S}/rapidxml.hpp ${S}/rapidxml_iterators.hpp \
        ${S}/rapidxml_print.hpp ${S}/rapidxml_utils.hpp ${D}${includedir}/rapidxml/
}

# Only rapidxml-dev carries files; it must not pull in an empty main package.
ALLOW_EMPTY:${PN} = "1"
BBCLASSEXTEND = "native nativesdk"

CVE_PRODUCT = "rapidxml"

# SPDX-License-Identifier: Apache-2.0
# The configuration parser's sources, one list for the Linux build (config/CMakeLists.txt)
# and the Windows build (src/windows.cmake).
set(CCOMM_CONFIG_SOURCES config.cpp xml_input.cpp text.cpp parser.cpp parser_signal.cpp cross_check.cpp
    extension_section.cpp outline.cpp config_json.cpp clock_section.cpp)

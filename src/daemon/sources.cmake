# SPDX-License-Identifier: Apache-2.0
# ccommd's library sources, for the Linux build (daemon/CMakeLists.txt) and the Windows
# build (src/windows.cmake): the portable files, and per platform the whole files that
# are its platform code (sockets, interfaces, privileges, key file, ptp4l, stop requests, the
# switch requester, service).
set(CCOMM_DAEMON_SOURCES daemon.cpp daemon_reload.cpp prepared_signals.cpp send_path.cpp send_catch_up.cpp receive_path.cpp
    supervisor.cpp
    system_view_writer.cpp transport_address.cpp auth.cpp ptp_state.cpp ptp_config.cpp node_identity.cpp
    send_cycle.cpp send_cycle_daemon.cpp switch_request.cpp)
set(CCOMM_DAEMON_POSIX_SOURCES transport_raw.cpp foreign_frames.cpp transport_udp.cpp node_interfaces_posix.cpp
    privileges.cpp auth_key_file_posix.cpp ptp_socket_posix.cpp stop_request_posix.cpp switch_request_posix.cpp service_none.cpp
    txtime_socket_posix.cpp board_net.cpp board_net_linux.cpp)
set(CCOMM_DAEMON_WINDOWS_SOURCES raw_ethernet_none.cpp transport_udp_windows.cpp node_interfaces_windows.cpp
    privileges_windows.cpp auth_key_file_windows.cpp ptp_socket_windows.cpp stop_request_windows.cpp
    switch_request_windows.cpp service_windows.cpp)

# SPDX-License-Identifier: Apache-2.0
# ccommd's library sources, for the Linux build (daemon/CMakeLists.txt) and the Windows
# build (src/windows.cmake), by room (README.md): the portable files, and per platform the
# whole files that are its platform code, each room's posix/ or windows/ folder (sockets,
# interfaces, privileges, key file, ptp4l, stop and switch requests, service).
set(CCOMM_DAEMON_SOURCES
    engine/daemon.cpp engine/daemon_reload.cpp engine/prepared_signals.cpp engine/send_path.cpp
    engine/send_catch_up.cpp engine/receive_path.cpp engine/supervisor.cpp engine/system_view_writer.cpp
    engine/send_cycle.cpp engine/send_cycle_daemon.cpp
    net/transport_address.cpp net/node_identity.cpp
    clock/ptp_state.cpp clock/ptp_config.cpp
    security/auth.cpp
    service/switch_instant.cpp service/io_threads.cpp service/reloader.cpp)
set(CCOMM_DAEMON_POSIX_SOURCES
    net/posix/transports.cpp net/posix/transport_raw.cpp net/posix/foreign_frames.cpp net/posix/transport_udp.cpp
    net/posix/node_interfaces.cpp net/posix/txtime_socket.cpp net/board_net.cpp net/posix/board_net_linux.cpp
    clock/posix/ptp_socket.cpp
    security/posix/privileges.cpp security/posix/auth_key_file.cpp
    service/posix/stop_request.cpp service/posix/switch_request.cpp service/posix/service.cpp
    service/posix/io_interrupt.cpp service/posix/board_net_mode.cpp)
set(CCOMM_DAEMON_WINDOWS_SOURCES
    net/windows/transports.cpp net/windows/foreign_frames.cpp net/windows/transport_udp.cpp net/windows/node_interfaces.cpp
    clock/windows/ptp_socket.cpp
    security/windows/privileges.cpp security/windows/auth_key_file.cpp
    service/windows/stop_request.cpp service/windows/switch_request.cpp service/windows/service.cpp
    service/windows/io_interrupt.cpp service/windows/board_net_mode.cpp)

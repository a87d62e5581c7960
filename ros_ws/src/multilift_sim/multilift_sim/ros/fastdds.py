"""Our participants' Fast DDS settings: a profile file every multilift process points Fast DDS
at before rclpy starts (`use_fastdds_profile`; run_node, the recorder and `scripts/multilift`
call it), unless the user names a profile of their own. No rclpy here: the command line sets it
before it knows whether a run needs ROS.
"""
from __future__ import annotations

import os
from pathlib import Path

# Our participants' Fast DDS (rmw_fastrtps, the default RMW) settings, unless the user names a
# profile file of their own:
# - UDP only, no shared memory. Fast DDS sends user data to a participant on the same host
#   through shared memory alone, with no fallback to UDP, and a process killed at the wrong
#   moment can leave port rings in /dev/shm that later participants reuse (SharedMemGlobal
#   opens a port by its number; upstream reports of the same symptom: eProsima/Fast-DDS#5053,
#   #5469). Seen here: a recorder that never received a follower's messages and a bridge that
#   received none of a run's, after a day of killed test processes. Our nodes on UDP leave
#   nothing in /dev/shm (the cost: benchmarks/results.md).
# - A reliable writer announces what it sent every 100 ms (3 s by default, and readers
#   acknowledge only then): a node's final flush (`wait_for_all_acked`) waited for that
#   (2.3 s at the end of a twin-lift run here; 0.02 s with this profile).
# - ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST: rmw_fastrtps (Jazzy) then gives the participant a
#   shared-memory transport whatever the profile says (seen here), so the profile keeps to this
#   machine itself (UDP on 127.0.0.1 alone, discovery by unicast to 127.0.0.1, as rmw's
#   LOCALHOST does) and the range our processes hand to rmw becomes SUBNET: they still find,
#   and are found by, LOCALHOST nodes on this machine, and nothing beyond it.
# With discovery by unicast to 127.0.0.1, a participant announces itself to the ports of the
# first participant ids only (Fast DDS's maxInitialPeersRange, 4 by default), and two
# participants of higher ids never learn of each other (Fast DDS relays no participant): a "V" of
# five (seven participants) hung at its start, the simulator never finding two followers (1 of 3
# runs here). So our participants announce themselves to this many ids: the processes of a V of
# 30 with its recorder, a live view and a few tools.
LOCALHOST_PARTICIPANTS = 64
# - Receive buffers of 4 MiB (RECEIVE_BUFFER; the kernel caps them at net.core.rmem_max): a
#   node's socket receives every topic it reads, and the recorder's took a lockstep run's
#   traffic of about 40 ms at the OS default (208 KiB) before the kernel dropped datagrams
#   (this machine counted 454,506 UDP receive-buffer errors after a day of tests). Our writers
#   resend what was dropped; a user's writer that keeps 10 messages and announces every 3 s
#   (Fast DDS's defaults) has overwritten them by then: seen as 6 of 50 commands missing from
#   a bag under two parallel test workers.
RECEIVE_BUFFER = 4 * 1024 * 1024  # [bytes]
_TRANSPORT = """    <transport_descriptor>
      <transport_id>multilift_udp</transport_id>
      <type>UDPv4</type>
      <receiveBufferSize>{receive}</receiveBufferSize>{whitelist}
    </transport_descriptor>"""
_LOCALHOST_TRANSPORT = """
      <interfaceWhiteList><address>127.0.0.1</address></interfaceWhiteList>
      <maxInitialPeersRange>{peers}</maxInitialPeersRange>""".format(peers=LOCALHOST_PARTICIPANTS)
_BUILTIN = """
      <builtin>{announcement}{localhost}
      </builtin>"""
_LOCALHOST_DISCOVERY = """
        <metatrafficUnicastLocatorList><locator/></metatrafficUnicastLocatorList>
        <initialPeersList>
          <locator><udpv4><address>127.0.0.1</address></udpv4></locator>
        </initialPeersList>"""
_ANNOUNCEMENT = """
        <discovery_config>
          <leaseAnnouncement><sec>0</sec><nanosec>{nanosec}</nanosec></leaseAnnouncement>
        </discovery_config>"""
_PROFILE = """<?xml version="1.0" encoding="UTF-8" ?>
<profiles xmlns="http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles">
  <transport_descriptors>
{transport}
  </transport_descriptors>
  <participant profile_name="multilift_participant" is_default_profile="true">
    <rtps>{discovery}
      <userTransports><transport_id>multilift_udp</transport_id></userTransports>
      <useBuiltinTransports>false</useBuiltinTransports>
    </rtps>
  </participant>
  <publisher profile_name="multilift_writer" is_default_profile="true">
    <times>
      <heartbeatPeriod><sec>0</sec><nanosec>100000000</nanosec></heartbeatPeriod>
    </times>
  </publisher>
</profiles>
"""
# A participant learns of one that starts after it only when that one hears its next
# announcement (Fast DDS: every 3 s by default; seen here under our LOCALHOST profile): the nodes
# of a run that lives a second at full speed were gone before they had found a live view started
# before them (0 of 6 short runs forwarded; 6 of 6 with this period). The live view
# (`multilift foxglove`) announces itself this often; nodes keep the default.
LIVE_VIEW_ANNOUNCEMENT = 0.1  # [s]


def fastdds_profile(localhost: bool, announcement: float | None = None) -> str:
    """Our profile's text: UDP only (on 127.0.0.1 alone, discovery by unicast to it, with
    `localhost`), the writer heartbeat, and with `announcement` [s] the participant's
    announcement period."""
    builtin = ''
    if localhost or announcement is not None:
        builtin = _BUILTIN.format(
            announcement='' if announcement is None else _ANNOUNCEMENT.format(
                nanosec=int(round(announcement * 1e9))),
            localhost=_LOCALHOST_DISCOVERY if localhost else '')
    return _PROFILE.format(
        transport=_TRANSPORT.format(receive=RECEIVE_BUFFER,
                                    whitelist=_LOCALHOST_TRANSPORT if localhost else ''),
        discovery=builtin)


FASTDDS_PROFILE = fastdds_profile(localhost=False)
FASTDDS_LOCALHOST_PROFILE = fastdds_profile(localhost=True)
_PROFILE_VARIABLES = ('FASTRTPS_DEFAULT_PROFILES_FILE', 'FASTDDS_DEFAULT_PROFILES_FILE')
_RANGE = 'ROS_AUTOMATIC_DISCOVERY_RANGE'


def use_fastdds_profile(announcement: float | None = None) -> Path | None:
    """Point Fast DDS at our profile (`fastdds_profile`: for ROS_AUTOMATIC_DISCOVERY_RANGE=
    LOCALHOST the localhost one; `announcement` [s] as there), written under the user's cache,
    before rclpy starts, unless a profile file is named already; the file, or None. Processes
    started from here inherit it."""
    if any(os.environ.get(name) for name in _PROFILE_VARIABLES):
        return None
    localhost = os.environ.get(_RANGE, '').upper() == 'LOCALHOST'
    text = fastdds_profile(localhost, announcement)
    cache = Path(os.environ.get('XDG_CACHE_HOME') or Path.home() / '.cache') / 'multilift'
    name = 'fastdds_profiles' + ('_localhost' if localhost else '') + (
        '' if announcement is None else f'_announce{announcement:g}s')
    path = cache / f'{name}.xml'
    try:
        if not path.is_file() or path.read_text() != text:
            cache.mkdir(parents=True, exist_ok=True)
            tmp = path.with_name(f'{path.name}.{os.getpid()}.tmp')
            tmp.write_text(text)
            tmp.replace(path)
    except OSError:  # no writable cache: Fast DDS's defaults, a slower exit
        return None
    os.environ['FASTRTPS_DEFAULT_PROFILES_FILE'] = str(path)
    if localhost:
        os.environ[_RANGE] = 'SUBNET'  # the profile keeps to this machine (see above)
    return path

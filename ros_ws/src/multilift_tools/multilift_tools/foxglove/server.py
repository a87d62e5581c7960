"""A Foxglove WebSocket protocol server (`FoxgloveServer`: the `websockets` package,
subprotocols foxglove.websocket.v1 and foxglove.sdk.v1) for the bridge of `multilift foxglove`,
on an asyncio loop in a thread of its own. A channel is registered before it is advertised; a
new subscription first gets the last REPLAY messages of its channel; each client has a queue of
CLIENT_BACKLOG messages, what does not fit is dropped and counted per topic.
"""
from __future__ import annotations

import asyncio
import collections
import json
import struct
import threading
import time
from typing import Any

CLIENT_BACKLOG = 200_000  # messages queued for one client before drops
REPLAY = 1000  # last messages of a channel a new subscription gets first (as transient_local)
SUBPROTOCOL = 'foxglove.sdk.v1'
SUBPROTOCOLS = ('foxglove.websocket.v1', SUBPROTOCOL)  # the app's, foxglove-sdk's
MESSAGE_DATA, TIME = 0x01, 0x02  # binary opcodes (server -> client)
CLIENT_MESSAGE_DATA = 0x01  # binary opcode (client -> server, capability clientPublish)


class _Client:
    def __init__(self, ws: Any) -> None:
        self.ws = ws
        self.subscriptions: dict[int, int] = {}  # subscription id -> channel id
        self.by_channel: dict[int, int] = {}  # channel id -> subscription id
        self.queue: collections.deque = collections.deque()
        self.ready = asyncio.Event()
        self.advertised: dict[int, tuple[str, str]] = {}  # its channel id -> (topic, type)


class FoxgloveServer:
    """A Foxglove WebSocket protocol server (the parts a live view uses: server info,
    advertise/unadvertise, subscribe/unsubscribe, message data, time, status; and clients'
    messages, capability clientPublish: a client advertises a channel (topic, `cdr`, a schema
    name such as geometry_msgs/msg/PoseStamped) and sends CDR bytes on it, handed to
    `on_publish(topic, type, data)` on the server's thread, data None when it advertises), on
    an asyncio loop in a thread of its own. `add_channel`, `remove_channel`, `log`,
    `broadcast_time` and `clear_session` may be called from any thread."""

    def __init__(self, host: str, port: int, name: str, metadata: dict[str, str],
                 log=print, on_publish=None) -> None:
        self.name, self.metadata, self.log_line = name, metadata, log
        self.on_publish = on_publish
        self.channels: dict[int, dict] = {}
        self._ids: dict[str, int] = {}  # topic -> channel id (kept, reused on return)
        self._lock = threading.Lock()
        self._clients: set[_Client] = set()
        self._pending: collections.deque = collections.deque()
        self._history: dict[int, collections.deque] = {}  # channel id -> (log_time, data)
        self._scheduled = False
        self.session_id = str(time.time_ns())
        self.dropped: collections.Counter = collections.Counter()  # topic -> messages
        self.loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self.loop.run_forever, daemon=True,
                                        name='foxglove-server')
        self._thread.start()
        try:
            self._server = asyncio.run_coroutine_threadsafe(self._serve(host, port),
                                                            self.loop).result()
        except OSError as error:
            self.loop.call_soon_threadsafe(self.loop.stop)
            self._thread.join(timeout=5)
            raise RuntimeError(str(error)) from None
        self.port = self._server.sockets[0].getsockname()[1]

    async def _serve(self, host: str, port: int):
        from websockets.asyncio.server import serve
        return await serve(self._handle, host, port, subprotocols=list(SUBPROTOCOLS),
                           compression=None, max_size=None, max_queue=None)

    # -- from any thread -------------------------------------------------------------------
    def add_channel(self, topic: str, schema_name: str, schema: str) -> int:
        """Register a channel (its id) and then advertise it."""
        with self._lock:
            channel_id = self._ids.setdefault(topic, len(self._ids) + 1)
            self.channels[channel_id] = {
                'id': channel_id, 'topic': topic, 'encoding': 'cdr', 'schemaName': schema_name,
                'schema': schema, 'schemaEncoding': 'ros2msg'}
        self._call(self._broadcast_json, {'op': 'advertise',
                                          'channels': [self.channels[channel_id]]})
        return channel_id

    def remove_channel(self, channel_id: int) -> None:
        with self._lock:
            self.channels.pop(channel_id, None)
        self._call(self._unadvertise, channel_id)

    def log(self, channel_id: int, log_time: int, data: bytes) -> None:
        """Send one message of a channel to every client subscribed to it."""
        self._pending.append((channel_id, log_time, data))
        if not self._scheduled:
            self._scheduled = True
            self._call(self._dispatch)

    def broadcast_time(self, t_ns: int) -> None:
        self._call(self._broadcast_binary, struct.pack('<BQ', TIME, max(0, t_ns)))

    def clear_session(self) -> None:
        """A new session id: clients reset their state (new server info)."""
        self.session_id = str(time.time_ns())
        self._call(self._broadcast_json, self._server_info())

    def stop(self) -> None:
        async def close() -> None:
            self._server.close()
            await self._server.wait_closed()
        try:
            asyncio.run_coroutine_threadsafe(close(), self.loop).result(timeout=5)
        except Exception:  # noqa: BLE001 - stopping anyway
            pass
        self.loop.call_soon_threadsafe(self.loop.stop)
        self._thread.join(timeout=5)

    def _call(self, function, *args) -> None:
        try:
            self.loop.call_soon_threadsafe(function, *args)
        except RuntimeError:  # the loop is closed: stopping
            pass

    # -- on the loop -----------------------------------------------------------------------
    def _server_info(self) -> dict:
        publish = ['clientPublish'] if self.on_publish is not None else []
        return {'op': 'serverInfo', 'name': self.name, 'capabilities': ['time', *publish],
                'supportedEncodings': ['cdr'] if publish else [],
                'metadata': dict(self.metadata),
                'sessionId': self.session_id}

    def _dispatch(self) -> None:
        self._scheduled = False
        pending, self._pending = self._pending, collections.deque()
        for channel_id, log_time, data in pending:
            history = self._history.get(channel_id)
            if history is None:
                history = self._history[channel_id] = collections.deque(maxlen=REPLAY)
            history.append((log_time, data))
            for client in self._clients:
                sub_id = client.by_channel.get(channel_id)
                if sub_id is None:
                    continue
                if len(client.queue) >= CLIENT_BACKLOG:
                    channel = self.channels.get(channel_id)
                    self.dropped[channel['topic'] if channel else '?'] += 1
                    continue
                client.queue.append(struct.pack('<BIQ', MESSAGE_DATA, sub_id, log_time) + data)
                client.ready.set()

    def _enqueue(self, client: _Client, frame) -> None:
        client.queue.append(frame)
        client.ready.set()

    def _broadcast_json(self, message: dict) -> None:
        text = json.dumps(message)
        for client in self._clients:
            self._enqueue(client, text)

    def _broadcast_binary(self, frame: bytes) -> None:
        for client in self._clients:
            self._enqueue(client, frame)

    def _unadvertise(self, channel_id: int) -> None:
        self._history.pop(channel_id, None)
        for client in self._clients:
            sub_id = client.by_channel.pop(channel_id, None)
            if sub_id is not None:
                client.subscriptions.pop(sub_id, None)
        self._broadcast_json({'op': 'unadvertise', 'channelIds': [channel_id]})

    async def _handle(self, ws) -> None:
        client = _Client(ws)
        self._enqueue(client, json.dumps(self._server_info()))
        with self._lock:
            channels = list(self.channels.values())
        if channels:
            self._enqueue(client, json.dumps({'op': 'advertise', 'channels': channels}))
        self._clients.add(client)
        writer = asyncio.ensure_future(self._write(client))
        try:
            async for text in ws:
                if isinstance(text, str):
                    self._on_client_message(client, text)
                else:
                    self._on_client_data(client, text)
        except Exception:  # noqa: BLE001 - a client that went away
            pass
        finally:
            self._clients.discard(client)
            writer.cancel()

    async def _write(self, client: _Client) -> None:
        while True:
            await client.ready.wait()
            client.ready.clear()
            while client.queue:
                await client.ws.send(client.queue.popleft())

    def _status(self, client: _Client, level: int, message: str) -> None:
        self._enqueue(client, json.dumps({'op': 'status', 'level': level, 'message': message}))

    def _on_client_message(self, client: _Client, text: str) -> None:
        try:
            message = json.loads(text)
        except ValueError:
            return
        if message.get('op') == 'subscribe':
            for sub in message.get('subscriptions', []):
                channel_id, sub_id = sub.get('channelId'), sub.get('id')
                if channel_id not in self.channels:
                    self._status(client, 2, f'Unknown channel ID: {channel_id}')
                    continue
                client.subscriptions[sub_id] = channel_id
                client.by_channel[channel_id] = sub_id
                # what the channel carried before this subscription (a client subscribes a
                # moment after the advertisement, when the publishers' kept messages may have
                # arrived already): the last REPLAY messages, then the live ones
                for log_time, data in self._history.get(channel_id, ()):
                    client.queue.append(struct.pack('<BIQ', MESSAGE_DATA, sub_id, log_time)
                                        + data)
                client.ready.set()
        elif message.get('op') == 'advertise' and self.on_publish is not None:
            for channel in message.get('channels', []):
                if channel.get('encoding') != 'cdr':
                    self._status(client, 2, f'channel {channel.get("topic")}: encoding '
                                 f'{channel.get("encoding")!r} (this server takes cdr)')
                    continue
                advertised = (channel.get('topic'), channel.get('schemaName'))
                client.advertised[channel.get('id')] = advertised
                try:  # the publisher made now: its readers match it before the first message
                    self.on_publish(*advertised, None)
                except Exception as error:  # noqa: BLE001 - told to the client
                    self._status(client, 2, f'{advertised[0]}: {error}')
        elif message.get('op') == 'unadvertise':
            for channel_id in message.get('channelIds', []):
                client.advertised.pop(channel_id, None)
        elif message.get('op') == 'unsubscribe':
            for sub_id in message.get('subscriptionIds', []):
                channel_id = client.subscriptions.pop(sub_id, None)
                if channel_id is not None:
                    client.by_channel.pop(channel_id, None)

    def _on_client_data(self, client: _Client, frame: bytes) -> None:
        """A client's message on a channel it advertised (opcode, channel id, CDR bytes)."""
        if len(frame) < 5 or frame[0] != CLIENT_MESSAGE_DATA or self.on_publish is None:
            return
        (channel_id,) = struct.unpack_from('<I', frame, 1)
        advertised = client.advertised.get(channel_id)
        if advertised is None:
            self._status(client, 2, f'Unknown client channel ID: {channel_id}')
            return
        try:
            self.on_publish(*advertised, bytes(frame[5:]))
        except Exception as error:  # noqa: BLE001 - told to the client, the server goes on
            self._status(client, 2, f'{advertised[0]}: {error}')

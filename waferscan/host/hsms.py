"""The equipment's HSMS transport: secsgem 0.3.0's, with the faults that lose a factory host's
connection mended. Everything plugs in through the settings' factories (``create_protocol``,
``create_connection``); secsgem itself is unchanged and a host may run it as it is.

What secsgem 0.3.0 does, and what the classes here do instead:

1. A TCP probe that connects and closes at once can leave the stock listener closed for good
   (the accepting thread of the last connection closes the next one's socket). Here one
   listening thread owns its socket for the whole life of the link.
2. The stock protocol starts dispatching before its state machine is connected: a quick
   Select.req is answered but the select is lost, and every data message is then rejected.
   Here the state is connected first, and the peer's bytes are read only after that.
3. A send with no connection waits for ever (and the stale message goes to the next host
   before its select). Here it fails at once: ``send_and_waitfor_response`` returns None and
   ``send_stream_function``/``send_response`` return False. A send waits at most T8 for the
   socket, a reply at most T3, and a lost connection ends every wait for a reply at once.
4. Every connection leaves one dispatching thread behind. Here both threads of a connection
   are stopped when it ends (joined, 1 s at most each; one still busy in a callback ends
   when the callback returns, and never serves the next connection).
5. GEM's communication state stays COMMUNICATING after the host leaves, so the next host's
   S1F13 exchange fails. ``attach(handler)`` resets it on every disconnection: call it once
   after making the handler (the protocol does not know its handler).
6. A second host while one is selected is refused, as HSMS has it: the listening socket is
   closed while a session is on (the second host's connect is refused: ECONNREFUSED) and
   opened again when the session ends.
7. ``close(handler, timeout)`` stops a handler in bounded time, never hanging.

A port that cannot be listened on (in use, an address not of this machine) raises OSError from
``handler.enable()``: the caller reports it (the CLI's exit 2, "port in use").

``MessageLog`` turns secsgem's message log into SML-like lines for one handler.
"""

from __future__ import annotations

import logging
import os
import queue
import select
import socket
import struct
import threading
import time
import weakref

import secsgem.common
import secsgem.hsms
from secsgem.gem.communication_state_machine import CommunicationState
from secsgem.common.tcp_connection import TcpConnection
from secsgem.hsms.message import HsmsBlock

from . import messages

_log = logging.getLogger(__name__)

ACCEPT_POLL_S = 0.2  # how often the listening thread looks whether the link is being disabled
JOIN_S = 1.0  # how long a connection's end waits for each of its threads


class Block:
    """One encoded block waiting to be written, and whether it was (the protocol's send queue
    holds these; secsgem's own kind can only be waited for without a bound)."""

    def __init__(self, data: bytes):
        self.data = data
        self.ok = False
        self._done = threading.Event()

    def resolve(self, result: bool):
        self.ok = bool(result)
        self._done.set()

    def sent(self, timeout_s: float) -> bool:
        """Whether the block was written within ``timeout_s`` seconds."""
        return self._done.wait(timeout_s) and self.ok


class SessionThreads:
    """The two threads of one HSMS connection: the receiver (writes queued blocks, cuts the
    received bytes into blocks) and the dispatcher (hands complete messages on, one at a time).
    A new pair is made for every connection, so a dispatcher still busy with the last one's
    message can never take the next one's."""

    def __init__(self, receive, dispatch, name: str):
        self._receive = receive
        self._dispatch = dispatch
        self._name = name
        self._stopped = False
        self._receive_wanted = threading.Event()
        self._blocks: queue.Queue = queue.Queue()
        self.threads = [
            threading.Thread(target=self._receiving, name=f"{name}_receiver", daemon=True),
            threading.Thread(target=self._dispatching, name=f"{name}_dispatcher", daemon=True),
        ]

    def start(self):
        for thread in self.threads:
            thread.start()

    def stop(self):
        """Stop both threads and join them (``JOIN_S`` at most each)."""
        self._stopped = True
        self._receive_wanted.set()
        self._blocks.put(None)
        for thread in self.threads:
            if thread.ident is not None and thread is not threading.current_thread():
                thread.join(JOIN_S)

    def trigger_receiver(self):
        self._receive_wanted.set()

    def queue_block(self, source, block):
        self._blocks.put((source, block))

    def _receiving(self):
        while not self._stopped:
            self._receive_wanted.wait()
            self._receive_wanted.clear()
            if self._stopped:
                break
            try:
                self._receive()
            except Exception:  # noqa: BLE001  a bad block must not end the connection's reading
                _log.warning("HSMS receiving failed", exc_info=True)

    def _dispatching(self):
        while True:
            item = self._blocks.get()
            if item is None or self._stopped:
                break
            try:
                self._dispatch(*item)
            except Exception:  # noqa: BLE001
                _log.warning("HSMS dispatching failed", exc_info=True)


class EquipmentProtocol(secsgem.hsms.HsmsProtocol):
    """secsgem's HSMS protocol with faults 2 to 4 of the module's list mended."""

    def __init__(self, settings):
        super().__init__(settings)
        self._thread = self._new_threads()

    def _new_threads(self) -> SessionThreads:
        name = self._settings.generate_thread_name("session")
        return SessionThreads(self._process_data, self._dispatch_block, name)

    def threads(self) -> list[threading.Thread]:
        """The link's threads that are running (the listening or connecting thread, the socket's
        reader, the session's receiver and dispatcher)."""
        found = list(self._thread.threads) + list(self._connection.threads())
        return [thread for thread in found if thread.is_alive()]

    def _on_connected(self, _):
        self._fail_queued_sends()
        self._receive_buffer.clear()
        self._thread = self._new_threads()
        self._connected = True
        self._connection_state.connect()  # before anything the peer sent is read
        self._thread.start()
        self.events.fire("connected", {"connection": self})

    def _on_disconnected(self, _):
        self._connected = False
        try:
            self._connection_state.disconnect()
        except Exception:  # noqa: BLE001  the threads must stop all the same
            _log.exception("HSMS state machine refused the disconnection")
        self._thread.stop()
        self._receive_buffer.clear()
        self._fail_queued_sends()
        for waiting in list(self._response_queues.values()):
            waiting.put_nowait(None)  # a reply will not come: the waiting send returns None
        self.events.fire("disconnected", {"connection": self})

    def _fail_queued_sends(self):
        while True:
            try:
                self._send_queue.get_nowait().resolve(False)
            except queue.Empty:
                return

    def send_message(self, message) -> bool:
        """Queue the message's blocks for the receiver thread to write; False at once without
        a connection, or when a block is not written within T8."""
        for block in message.blocks:
            if not self._connected:
                return False
            pending = Block(block.encode())
            self._send_queue.put(pending)
            self._thread.trigger_receiver()
            if not pending.sent(self._settings.timeouts.t8):
                return False
        return True

    def _process_received_data(self):
        # secsgem waits here for the rest of a partly received message, holding the thread
        # for ever if the connection ends first; the rest comes with the next data anyway.
        while len(self._receive_buffer) >= 4:
            length = struct.unpack(">L", bytes(self._receive_buffer.peek(4)))[0] + 4
            if len(self._receive_buffer) < length:
                return
            self._thread.queue_block(self, HsmsBlock.decode(self._receive_buffer.pop(length)))

    def _on_linktest_timer(self):
        self.send_linktest_req()
        if self._connected:  # secsgem restarts the timer even after the connection ended
            self._start_linktest_timer()


class SessionConnection(TcpConnection):
    """A TCP link that one long-lived thread opens, one session at a time; ``_next_socket``
    (listening or connecting) gives the next session's socket. The protocol hears of a new
    session before its socket is read."""

    def __init__(self, settings):
        super().__init__(settings)
        self._enabled = False
        self._wake = threading.Event()
        self._opener: threading.Thread | None = None
        self._reader: threading.Thread | None = None

    def threads(self) -> list[threading.Thread]:
        return [thread for thread in (self._opener, self._reader) if thread is not None]

    def enable(self):
        if self._enabled:
            return
        self._prepare()
        self._enabled = True
        self._wake.clear()
        self._opener = threading.Thread(target=self._open_sessions, daemon=True,
                                        name=self._settings.generate_thread_name("opener"))
        self._opener.start()

    def disable(self):
        if not self._enabled:
            return
        self._enabled = False
        self._wake.set()
        if self._opener is not None and self._opener is not threading.current_thread():
            self._opener.join(JOIN_S + ACCEPT_POLL_S)
        self.disconnect()

    def disconnect(self):
        """End the session (a Separate.req goes first) and wait for its reader, T8 at most."""
        reader = self._reader
        if reader is None or not reader.is_alive():
            return
        self._disconnecting = True
        self._stop_thread = True
        if reader is not threading.current_thread():
            reader.join(self._settings.timeouts.t8)
        self._disconnecting = False

    def _in_session(self) -> bool:
        return self._reader is not None and self._reader.is_alive()

    def _open_sessions(self):
        try:
            while self._enabled:
                if self._in_session():
                    self._wake.wait(0.05)
                    continue
                sock = self._next_socket()
                if sock is not None and self._enabled:
                    self._begin(sock)
                elif sock is not None:
                    sock.close()
        finally:
            self._release()

    def _begin(self, sock: socket.socket):
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_KEEPALIVE, 1)
        # A reply goes out at once: with Nagle's algorithm on, a small message written while
        # the peer delays its ACK waits for it (about 40 ms a round trip on Linux).
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        sock.setblocking(False)
        self._sock = sock
        self._connected = True
        try:
            self.on_connected({"source": self})
        except Exception:  # noqa: BLE001
            _log.exception("HSMS connected handler failed")
        self._start_receiver()

    def _start_receiver(self):
        # secsgem's reader loop, in a daemon thread this class can join.
        self._reader = threading.Thread(target=self._TcpConnection__receiver_thread, daemon=True,
                                        name=self._settings.generate_thread_name("reader"))
        self._reader.start()

    def _prepare(self):
        """Called by enable() before the opening thread starts."""

    def _next_socket(self) -> socket.socket | None:
        raise NotImplementedError

    def _release(self):
        """Called by the opening thread when it ends."""


class Listener(SessionConnection):
    """Passive side: listens on address:port, takes one host at a time (the listening socket is
    closed during a session, so a second host is refused) and listens again after it."""

    def __init__(self, settings):
        super().__init__(settings)
        self._listening: socket.socket | None = None
        self._bind_failed = False

    def _bind(self) -> socket.socket:
        sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        try:
            if os.name != "nt":  # on Windows SO_REUSEADDR would let two listeners share a port
                sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            sock.bind((self._settings.address, self._settings.port))
            sock.listen(1)
        except OSError:
            sock.close()
            raise
        return sock

    def _prepare(self):
        self._listening = self._bind()  # OSError to enable()'s caller: port in use, bad address

    def _next_socket(self):
        if self._listening is None:
            try:
                self._listening = self._bind()
                self._bind_failed = False
            except OSError as error:
                if not self._bind_failed:
                    _log.warning("cannot listen again on %s:%s: %s", self._settings.address,
                                 self._settings.port, error)
                self._bind_failed = True
                self._wake.wait(ACCEPT_POLL_S)
                return None
        try:
            if not select.select([self._listening], [], [], ACCEPT_POLL_S)[0]:
                return None
            sock, _ = self._listening.accept()
        except OSError:
            return None
        self._listening.close()
        self._listening = None
        return sock

    def _release(self):
        if self._listening is not None:
            self._listening.close()
            self._listening = None


class Dialer(SessionConnection):
    """Active side: connects to address:port, and again T5 seconds after a failed attempt or
    an ended session (HSMS's connect separation timeout)."""

    def _prepare(self):
        self._attempts = 0

    def _next_socket(self):
        t5 = max(float(self._settings.timeouts.t5), 0.1)
        if self._attempts and self._wake.wait(t5):
            return None  # disabled while waiting
        self._attempts += 1
        try:
            return socket.create_connection((self._settings.address, self._settings.port),
                                            timeout=max(t5, 1.0))
        except OSError:
            return None


class EquipmentSettings(secsgem.hsms.HsmsSettings):
    """HSMS settings whose protocol and connection are this module's."""

    def create_protocol(self):
        return EquipmentProtocol(self)

    def create_connection(self):
        if self.connect_mode == secsgem.hsms.HsmsConnectMode.PASSIVE:
            return Listener(self)
        return Dialer(self)


def settings(address: str, port: int, active: bool = False, session_id: int = 0,
             registry=None, **timeouts) -> EquipmentSettings:
    """Settings for the equipment's side of a link: passive listens on address:port, active
    connects to it (again every T5 seconds). ``registry`` defaults to a fresh
    ``messages.registry()``; ``timeouts`` are secsgem's t3..t8 (seconds) and
    establish_communication_timeout (an unknown name is a ValueError)."""
    mode = secsgem.hsms.HsmsConnectMode
    return EquipmentSettings(
        address=address,
        port=port,
        connect_mode=mode.ACTIVE if active else mode.PASSIVE,
        device_type=secsgem.common.DeviceType.EQUIPMENT,
        session_id=session_id,
        streams_functions=registry if registry is not None else messages.registry(),
        **timeouts,
    )


_attached: weakref.WeakSet = weakref.WeakSet()


def attach(handler):
    """Reset ``handler``'s GEM communication state whenever its connection ends (secsgem 0.3.0
    never does), so the next host's S1F13 exchange starts afresh. Once per handler; returns it.
    The handler's ``on_connection_closed`` is called first, as secsgem meant."""
    if handler in _attached:
        return handler
    _attached.add(handler)
    reference = weakref.ref(handler)
    handler.events.disconnected.register(lambda data: _communication_closed(reference(), data))
    return handler


def _communication_closed(handler, data):
    if handler is None:
        return
    try:
        handler.on_connection_closed(data)
        state = handler.communication_state
        if state.current not in (CommunicationState.DISABLED,
                                 CommunicationState.NOT_COMMUNICATING):
            # waiting for an S1F13 answer or a retry: timers that would run on without a host
            state.disable()
            state.enable()
    except Exception:  # noqa: BLE001
        _log.exception("resetting the GEM communication state failed")


def close(handler, timeout: float = 5.0) -> bool:
    """Disable ``handler`` and wait for the link's threads to end, ``timeout`` seconds at most
    in all. True if everything stopped; False if not in time (the rest are daemon threads, so
    the process can still exit) or if disabling raised (logged). Closing twice is harmless."""
    deadline = time.monotonic() + timeout
    failed = []

    state = getattr(handler, "communication_state", None)
    # closed before: GEM's state machine would refuse a second disable
    closed_before = state is not None and state.current == CommunicationState.DISABLED

    def disable():
        if closed_before:
            return
        try:
            handler.disable()
        except Exception as error:  # noqa: BLE001
            failed.append(error)
            _log.exception("disabling the HSMS link failed")

    stopper = threading.Thread(target=disable, daemon=True, name="hsms_close")
    stopper.start()
    stopper.join(timeout)
    if stopper.is_alive():
        return False
    threads = getattr(handler.protocol, "threads", lambda: [])
    while threads() and time.monotonic() < deadline:
        time.sleep(0.01)
    return not threads() and not failed


# --- the message log ----------------------------------------------------------------------------

COMMUNICATION_LOGGER = "communication"  # secsgem logs every message sent or received here
_log_state_lock = threading.Lock()
_log_count = 0
_log_saved: tuple[int, bool] | None = None


class MessageLog(logging.Handler):
    """A logging handler that passes each message secsgem sends or receives to ``callback`` as
    text: "< S1F13 W" and the message's SML lines for one received, "> ..." for one sent,
    "< Select.req" for an HSMS control message. ``name`` (a settings' ``.name``) keeps only
    that handler's messages, when a host and an equipment share the process.

    The callback runs on secsgem's threads, outside the handler's lock (secsgem logs from
    several threads; a callback waiting on one of them must not deadlock): it must be
    thread-safe and quick. Attach with ``attach_log``."""

    def __init__(self, callback, name: str | None = None):
        super().__init__(logging.INFO)
        self.callback = callback
        self.name_wanted = name

    def handle(self, record):
        # logging.Handler.handle would call emit under the handler's lock.
        if record.levelno >= self.level and self.filter(record):
            self.emit(record)
        return record

    def filter(self, record):
        if self.name_wanted is not None and getattr(record, "remoteName", None) != self.name_wanted:
            return False
        return super().filter(record)

    def emit(self, record):
        try:
            self.callback(message_text(record))
        except Exception:  # noqa: BLE001
            self.handleError(record)


def message_text(record: logging.LogRecord) -> str:
    """The line(s) of one of secsgem's message records: direction, then the SML-like text."""
    direction = str(record.msg)[:1]
    args = record.args if isinstance(record.args, tuple) else ()
    if len(args) >= 2:
        body = args[1]
        text = body.strip() if isinstance(body, str) else messages.sml(body)
        return f"{direction} {text}"
    return record.getMessage()


def attach_log(callback, name: str | None = None) -> MessageLog:
    """Start passing secsgem's messages to ``callback`` (see MessageLog); ``detach_log`` ends it.
    While at least one MessageLog is attached, the "communication" logger logs at INFO and
    does not pass its records on to the root logger's handlers (they would print every message
    twice, or flood a console); both are restored when the last one is detached. No other
    logger is touched."""
    global _log_count, _log_saved
    log = MessageLog(callback, name)
    logger = logging.getLogger(COMMUNICATION_LOGGER)
    with _log_state_lock:
        if _log_count == 0:
            _log_saved = (logger.level, logger.propagate)
            if logger.getEffectiveLevel() > logging.INFO:
                logger.setLevel(logging.INFO)
            logger.propagate = False
        _log_count += 1
        logger.addHandler(log)
    return log


def detach_log(log: MessageLog) -> None:
    """Stop a MessageLog started by ``attach_log``."""
    global _log_count, _log_saved
    logger = logging.getLogger(COMMUNICATION_LOGGER)
    with _log_state_lock:
        if log not in logger.handlers:
            return
        logger.removeHandler(log)
        _log_count -= 1
        if _log_count == 0 and _log_saved is not None:
            logger.setLevel(_log_saved[0])
            logger.propagate = _log_saved[1]
            _log_saved = None

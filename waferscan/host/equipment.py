"""The equipment a factory host talks to (SPEC §14): a GEM equipment handler of ``secsgem`` whose
load ports are a ``HostLink``'s.

- Status variables (S1F3/4): each port's CarrierID, SlotMap and SlotMapStatus, numbered by the
  IDs file's bases (base + port number).
- Collection events (S2F33/35/37 set them up, S6F11 carries them): one per slot-map transition
  and one for a cancelled carrier, with the data values PortID, CarrierID, SlotMap,
  SlotMapStatus and Reason of the transition being reported. The report is built when the
  transition happens (not when a thread gets round to sending it), and events are sent one at a
  time in the order they happened, after the reply to the message that caused them.
- S3F17/18 carrier actions and S14F1/2 GetAttr go to the ports' E87 model (``host.e87``).
- What the equipment cannot understand is answered with stream 9: S9F3 (unknown stream), S9F5
  (unknown function), S9F7 (data it cannot read).
"""

from __future__ import annotations

import itertools
import queue
import threading

import secsgem.gem
from secsgem.secs import variables as V

from . import hsms, messages
from .e87 import INVALID_DATA, UNKNOWN_OBJECT_INSTANCE, Error

# The transition's data, by the IDs file's [data] keys, as SECS-II items.
_DATA_TYPES = {"port_id": V.U1, "carrier_id": V.String, "slot_map": V.Array,
               "slot_map_status": V.U1, "reason": V.String}
_DATA_NAMES = {"port_id": "PortID", "carrier_id": "CarrierID", "slot_map": "SlotMap",
               "slot_map_status": "SlotMapStatus", "reason": "Reason"}
_STATUS_NAMES = {"carrier_id": "CarrierID", "slot_map": "SlotMap",
                 "slot_map_status": "SlotMapStatus"}
# E87 status -> the IDs file's [events] key of its collection event (None: cancelled)
_EVENT_OF_STATUS = {0: "slot_map_not_read", 1: "waiting_for_host", 2: "verification_ok",
                    3: "verification_failed", None: "carrier_cancelled"}
UNKNOWN_OBJECT_TYPE = 6  # ERRCODE (SEMI E5)


class LoadPortEquipment(secsgem.gem.GemEquipmentHandler):
    """The equipment of ``link`` (a ``host.link.HostLink``) on HSMS ``settings``
    (``host.hsms.settings``). ``log(text)`` receives what an operator reads: state changes,
    events sent or not, refusals."""

    def __init__(self, settings, link, log=None):
        super().__init__(settings)
        hsms.attach(self)
        self.link = link
        self.ids = ids = link.ids
        self.log = log or (lambda text: None)
        self._mdln, self._softrev = ids.mdln, ids.softrev
        self._status_of = {}  # SVID -> (key, port)
        for port in link.port_ids:
            for key, name in _STATUS_NAMES.items():
                svid = ids.status_id(key, port.number)
                self._status_of[svid] = (key, port.number)
                self.status_variables.update({svid: secsgem.gem.StatusVariable(
                    svid, f"Port{port.number}{name}", "", _DATA_TYPES[key])})
        self._data_of = {dvid: key for key, dvid in ids.data.items()}
        self.data_values.update({dvid: secsgem.gem.DataValue(
            dvid, _DATA_NAMES[key], _DATA_TYPES[key])
            for key, dvid in ids.data.items()})
        self.collection_events.update({ceid: secsgem.gem.CollectionEvent(
            ceid, key, list(ids.data.values())) for key, ceid in ids.events.items()})
        self.register_stream_function(3, 17, self._on_carrier_action)
        self.register_stream_function(14, 1, self._on_get_attributes)
        self._reporting = threading.Lock()  # builds one event's reports at a time
        self._transition = None  # the transition whose data values are being read
        self._data_ids = itertools.count(1)
        self._held = threading.local()  # events made while handling a message wait for its reply
        self._last = {}  # CEID -> its last transition (S6F15)
        self._events = queue.Queue()
        self._sender = threading.Thread(target=self._send_events, name="waferscan-host-events",
                                        daemon=True)
        self._sender.start()

    # --- values --------------------------------------------------------------------------

    def on_sv_value_request(self, svid, status_variable):
        key, number = self._status_of[status_variable.svid]
        port = self.link.ports.port(number)
        if key == "carrier_id":
            return V.String(port.carrier_id or "")
        if key == "slot_map":
            return messages.slot_map_item(port.slot_map or port.unread_map())
        return V.U1(port.status)

    def on_dv_value_request(self, dvid, data_value):
        t = self._transition
        key = self._data_of[data_value.dvid]
        if t is None:  # asked outside an event (S6F15 before the event happened)
            return messages.slot_map_item(()) if key == "slot_map" else _DATA_TYPES[key](
                "" if _DATA_TYPES[key] is V.String else 0)
        if key == "port_id":
            return V.U1(t.port)
        if key == "carrier_id":
            return V.String(t.carrier_id)
        if key == "slot_map":
            return messages.slot_map_item(t.slot_map)
        if key == "slot_map_status":
            return V.U1(0 if t.status is None else t.status)
        return V.String(t.reason)

    # --- events --------------------------------------------------------------------------

    def report(self, transition):
        """Send the collection event of ``transition`` if the host linked and enabled it. The
        S6F11 is built now, with this transition's data, and queued now (events leave in the
        order their states changed); one made while a host's message is handled on this
        thread leaves after that message's reply. A fault here is logged, never raised into
        the state change that reported it."""
        key = _EVENT_OF_STATUS[transition.status]
        ceid = self.ids.events[key]
        try:
            with self._reporting:
                self._last[ceid] = transition
                link = self.registered_collection_events.get(ceid)
                if link is None or not link.enabled:
                    self.log(f"event {ceid} ({key}) not sent: the host has not linked and "
                             "enabled it")
                    return
                self._transition = transition
                try:
                    reports = [{"RPTID": V.U4(r["RPTID"]), "V": r["V"]}
                               for r in self._build_collection_event(ceid)]
                finally:
                    self._transition = None
                s6f11 = self.stream_function(6, 11)({"DATAID": V.U4(next(self._data_ids)),
                                                      "CEID": V.U4(ceid), "RPT": reports})
                self._events.put((s6f11, getattr(self._held, "reply_sent", None)))
        except Exception as exc:  # noqa: BLE001 (the state changed: only its event is lost)
            self.log(f"event {ceid} ({key}) not sent: {type(exc).__name__}: {exc}")

    def _send_events(self):
        from secsgem.gem.communication_state_machine import CommunicationState

        while True:
            item = self._events.get()
            if item is None:
                return
            s6f11, reply_sent = item
            if reply_sent is not None:
                reply_sent.wait(self.settings.timeouts.t3)
            if self.communication_state.current != CommunicationState.COMMUNICATING:
                # E30: no data messages before communications are established
                self.log(f"event {s6f11.CEID.get()} not sent: no host communicating")
                continue
            if self.send_and_waitfor_response(s6f11) is None:
                self.log(f"event {s6f11.CEID.get()} not acknowledged: no host, or no answer "
                         "within T3")

    # The host's report set-up (S2F33/35/37) and its event report request (S6F15) change or
    # read what report() builds from: one at a time with it.

    def _on_s02f33(self, handler, message):
        with self._reporting:
            return super()._on_s02f33(handler, message)

    def _on_s02f35(self, handler, message):
        with self._reporting:
            return super()._on_s02f35(handler, message)

    def _on_s02f37(self, handler, message):
        with self._reporting:
            return super()._on_s02f37(handler, message)

    def _on_s06f15(self, handler, message):
        """S6F16: the event's reports with the data of its last occurrence (empty values
        when it has not happened yet)."""
        ceid = self.settings.streams_functions.decode(message).get()
        with self._reporting:
            self._transition = self._last.get(ceid)
            try:
                return super()._on_s06f15(handler, message)
            finally:
                self._transition = None

    def close(self, timeout=5.0):
        """Stop the link and the event sender; True if everything stopped in time."""
        self._events.put(None)
        stopped = hsms.close(self, timeout)
        self._sender.join(timeout)
        return stopped and not self._sender.is_alive()

    # --- messages ------------------------------------------------------------------------

    def _handle_stream_function(self, message):
        decoded = self.settings.streams_functions.decode(message)
        if isinstance(decoded, messages.Undecodable):
            self.log(f"answered S9F{decoded.s9_function}: {decoded!r}")
            self.send_response(self.stream_function(9, decoded.s9_function)(
                message.header.encode()), message.header.system)
            return None
        self._held.reply_sent = reply_sent = threading.Event()
        try:
            return super()._handle_stream_function(message)
        finally:
            self._held.reply_sent = None
            reply_sent.set()  # the events this message made may follow its reply now

    def _on_carrier_action(self, handler, message):
        request = self.settings.streams_functions.decode(message)
        action, carrier_id = request.CARRIERACTION.get(), request.CARRIERID.get()
        attributes, wrong = [], []
        for attribute in request.CATTRS:
            name = attribute.ATTRID.get()
            if name == "SlotMap" and not messages.is_u1_list(attribute.ATTRDATA):
                wrong.append(Error(7, "SlotMap: expected a list of U1 (SEMI E87), got "
                                      f"{messages.sml(attribute.ATTRDATA)[:80]}"))
                continue
            attributes.append((name, messages.plain(attribute.ATTRDATA)))
        port = request.PTN.get()
        if not isinstance(port, int):  # a PTN of several values (<U1 1 2>)
            wrong.append(Error(7, f"PTN: expected one port number, got {port!r:.40}"))
        if wrong:
            caack, errors = INVALID_DATA, wrong
        else:
            reply = self.link.carrier_action(action, carrier_id, port, attributes)
            caack, errors = reply.caack, reply.errors
        self.log(f"S3F17 {action} {carrier_id!r}: CAACK {caack}"
                 + "".join(f"; {e.code} {e.text}" for e in errors))
        return self.stream_function(3, 18)({
            "CAACK": caack, "ERRORS": [{"ERRCODE": V.U4(e.code), "ERRTEXT": e.text[:120]}
                                       for e in errors]})

    def _on_get_attributes(self, handler, message):
        request = self.settings.streams_functions.decode(message)
        object_type, names = request.OBJTYPE.get(), list(request.ATTRID.get())
        data, errors = [], []
        for object_id in request.OBJID.get():
            found = None
            if object_type == "Carrier":
                found = self.link.ports.attributes(object_id, names)
                if found is None:
                    errors.append(Error(UNKNOWN_OBJECT_INSTANCE, f"no carrier {object_id!r}"))
            else:
                errors.append(Error(UNKNOWN_OBJECT_TYPE, f"unknown object type {object_type!r}"
                                    f" (this equipment has Carrier objects)"))
            values, missing = found or ([], [])
            errors.extend(missing)
            data.append({"OBJID": object_id, "ATTRIBS": [
                {"ATTRID": name, "ATTRDATA": messages.typed(value)} for name, value in values]})
        return self.stream_function(14, 2)({
            "DATA": data, "ERRORS": {"OBJACK": 1 if errors else 0, "ERROR": [
                {"ERRCODE": V.U4(e.code), "ERRTEXT": e.text[:120]} for e in errors]}})


"""SECS-II messages of the host link that secsgem 0.3.0 lacks or types differently, a
per-connection registry that decodes every message without raising, and typed values.

secsgem has no stream 3: SEMI E87's carrier action request S3F17 and its answer S3F18 are
defined here through secsgem's own extension points (data-item and stream-function classes
in a registry given to the connection's settings; nothing in secsgem is changed). A host
must be able to decode them too: a host built on secsgem uses ``registry()`` as well.

SECS-II is typed on the wire: a host that sends its SlotMap as a list of U1 expects U1 back.
``typed`` turns plain Python into the wire types the host link uses, ``plain`` reads a decoded
item back, and ``is_u1_list`` tells whether a host sent exactly a list of U1.

>>> plain(typed([1, 0, 3]))
[1, 0, 3]
>>> is_u1_list(slot_map_item([1, 3])), is_u1_list(typed(["A", "B"]))
(True, False)
"""

from __future__ import annotations

from secsgem.secs import variables as V
from secsgem.secs.data_items import (
    ATTRDATA,
    ATTRID,
    DATAID,
    ERRTEXT,
    OBJACK,
    OBJID,
    DataItemBase,
)
from secsgem.secs.functions import SecsStreamFunction, StreamsFunctions
from secsgem.secs.variables.dynamic import ANYVALUE

_INTEGERS = [V.U1, V.U2, V.U4, V.U8, V.I1, V.I2, V.I4, V.I8]
MAX_U1 = 255
MAX_U4 = 2**32 - 1
MIN_I4 = -(2**31)


# --- data items (E5 / E87) ---------------------------------------------------------------
# secsgem names a list's field after the data-item class: these names are the dict keys when
# a message is built and the attributes when it is read.


class CARRIERACTION(DataItemBase):
    """E87 carrier action of S3F17 (A): ProceedWithCarrier, CancelCarrier, ..."""

    name = "CARRIERACTION"
    __type__ = V.String


class CARRIERID(DataItemBase):
    """E87 carrier ID (A)."""

    name = "CARRIERID"
    __type__ = V.String


class PTN(DataItemBase):
    """Load port number. Any integer type is accepted from a host (some send U4); a plain int
    is sent as U1, E87's usual type. A single fixed type would make a whole S3F17 that uses
    another one undecodable."""

    name = "PTN"
    __type__ = V.Dynamic
    __allowedtypes__ = list(_INTEGERS)


class CAACK(DataItemBase):
    """Carrier action acknowledge (U1): 0 done, 1 invalid command, 2 cannot perform now,
    3 invalid data or argument, 4 acknowledged, done later, 5 rejected, invalid state."""

    name = "CAACK"
    __type__ = V.U1
    __count__ = 1


class ERRCODE(DataItemBase):
    """Error code. E5 allows any of U1..U8 and I1..I8 and a host must accept each; this link
    sends U4 (the first type listed), in S3F18 and S14F2 alike. secsgem's own ERRCODE knows
    only I1..I8 and would send a small code as I1, and could not decode a host's U4."""

    name = "ERRCODE"
    __type__ = V.Dynamic
    __allowedtypes__ = [V.U4, V.U1, V.U2, V.U8, V.I1, V.I2, V.I4, V.I8]


# --- stream functions ----------------------------------------------------------------------
# In a data format a list of one element is an array (L n of it), a list of several a fixed
# list, and a leading text names the list.


class SecsS03F17(SecsStreamFunction):
    """Carrier action request, host to equipment (W):
    <L5 DATAID CARRIERACTION CARRIERID PTN <L n <L2 ATTRID ATTRDATA>>>; the attribute list
    is the field CATTRS."""

    _stream = 3
    _function = 17
    _data_format = [DATAID, CARRIERACTION, CARRIERID, PTN, [["CATTRS", ATTRID, ATTRDATA]]]
    _to_host = False
    _to_equipment = True
    _has_reply = True
    _is_reply_required = True
    _is_multi_block = True


class SecsS03F18(SecsStreamFunction):
    """Carrier action acknowledge, equipment to host: <L2 CAACK <L n <L2 ERRCODE ERRTEXT>>>;
    the error list is the field ERRORS."""

    _stream = 3
    _function = 18
    _data_format = [CAACK, [["ERRORS", ERRCODE, ERRTEXT]]]
    _to_host = True
    _to_equipment = False
    _has_reply = False
    _is_reply_required = False
    _is_multi_block = True


class SecsS14F02(SecsStreamFunction):
    """GetAttr data, secsgem's layout with this module's ERRCODE (U4 sent, any integer type
    decoded): <L2 <L n <L2 OBJID <L n <L2 ATTRID ATTRDATA>>>>
    <L2 OBJACK <L n <L2 ERRCODE ERRTEXT>>>>, fields DATA (ATTRIBS) and ERRORS (ERROR).
    A host on stock secsgem decodes ERRCODE as I1..I8 only, so it reads an S14F2 with errors
    only through ``registry()``; an E5 host accepts U4."""

    _stream = 14
    _function = 2
    _data_format = [
        [["DATA", OBJID, [["ATTRIBS", ATTRID, ATTRDATA]]]],
        ["ERRORS", OBJACK, [["ERROR", ERRCODE, ERRTEXT]]],
    ]
    _to_host = True
    _to_equipment = True
    _has_reply = False
    _is_reply_required = False
    _is_multi_block = True


DATA_ITEMS = (CARRIERACTION, CARRIERID, PTN, CAACK, ERRCODE)
FUNCTIONS = (SecsS03F17, SecsS03F18, SecsS14F02)


# --- the registry ---------------------------------------------------------------------------


class Undecodable:
    """What ``Registry.decode`` gives for a message it cannot decode: its stream and function,
    whether it wants a reply, why it failed (``error``) and the stream 9 function that answers
    it (``s9_function``: 3 unknown stream, 5 unknown function, 7 illegal data). ``mhead`` is
    the message's 10-byte header, the body of that S9 message."""

    def __init__(self, message, error, s9_function):
        self.message = message
        self.stream = message.header.stream
        self.function = message.header.function
        self.reply_wanted = bool(message.header.require_response)
        self.error = error
        self.s9_function = s9_function

    @property
    def mhead(self) -> bytes:
        return self.message.header.encode()

    def __repr__(self):
        wait = " W" if self.reply_wanted else ""
        reason = str(self.error).splitlines()[0] if str(self.error) else type(self.error).__name__
        return f"S{self.stream}F{self.function}{wait} <undecodable: {reason}> ."


class Registry(StreamsFunctions):
    """secsgem's streams and functions with this module's, decoding without raising.

    secsgem's HSMS layer decodes each data message before it dispatches it (to log it) and
    drops the message silently when decoding raises: the host would wait T3 for nothing.
    Here such a message decodes to an ``Undecodable``, so it is logged, dispatched, and the
    equipment can answer it with the S9 function the Undecodable names. A missing message
    (None, a reply that never came) still raises ValueError, as in secsgem."""

    def decode(self, message):
        if message is None:
            raise ValueError("Decoding failed, missing message")
        stream, function = message.header.stream, message.header.function
        if self.function(stream, function) is None:
            known_stream = bool(self.stream(stream))
            return Undecodable(message, f"no S{stream}F{function} defined",
                               5 if known_stream else 3)
        try:
            return super().decode(message)
        except Exception as error:  # noqa: BLE001  any decoding failure is illegal data
            return Undecodable(message, error, 7)


def registry() -> Registry:
    """A fresh registry for one connection's settings (secsgem keeps per-connection state in
    it): secsgem's definitions, this module's data items and functions, tolerant decoding."""
    fresh = Registry()  # a copy of secsgem's function list and fresh data items
    for item in DATA_ITEMS:
        fresh.data_items.update(item)
    for function in FUNCTIONS:
        fresh.update(function)
    return fresh


# --- typed values -----------------------------------------------------------------------------


def _is_int(value) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _integer(value: int) -> V.Base:
    if 0 <= value <= MAX_U1:
        return V.U1(value)
    if 0 <= value <= MAX_U4:
        return V.U4(value)
    if value > MAX_U4:
        return V.U8(value)
    return V.I4(value) if value >= MIN_I4 else V.I8(value)


def typed(value) -> V.Base:
    """The secsgem variable the host link sends for a plain Python value (S1F4 status
    variables, S6F11 report values, S14F2 attributes):

    - bool -> Boolean; int -> U1 if 0..255, else U4 (U8 above U4), negative -> I4 (I8 below);
      float -> F8; str -> A (ASCII); bytes -> B;
    - a list or tuple of ints -> <L n <U1>...> if all are 0..255 (E87's SlotMap), else a list
      of U4 (or of each int's own type when some are negative or beyond U4);
    - any other list or tuple -> <L n> of each item typed, nested lists included;
    - a secsgem variable is returned as it is.

    >>> typed(25), typed(300), typed(-1), typed("PRODUCT")
    (<U1 25 >, <U4 300 >, <I4 -1 >, <A "PRODUCT">)
    """
    if isinstance(value, V.Base):
        return value
    if isinstance(value, bool):
        return V.Boolean(value)
    if _is_int(value):
        return _integer(value)
    if isinstance(value, float):
        return V.F8(value)
    if isinstance(value, str):
        return V.String(value)
    if isinstance(value, (bytes, bytearray)):
        return V.Binary(bytes(value))
    if isinstance(value, (list, tuple)):
        items = list(value)
        if items and all(_is_int(item) for item in items):
            if all(0 <= item <= MAX_U1 for item in items):
                return slot_map_item(items)
            if all(0 <= item <= MAX_U4 for item in items):
                return V.Array(V.U4, items)
        return V.Array(ANYVALUE, [typed(item) for item in items])
    raise TypeError(f"no SECS-II type for {type(value).__name__} {value!r}")


def slot_map_item(values) -> V.Array:
    """<L n <U1 v>...>: a list of U1 items, E87's SlotMap (not the single U1 array item
    <U1 v v ...> that ``V.U1(values)`` would make)."""
    return V.Array(V.U1, [int(value) for value in values])


def _unwrap(item):
    """The variable inside a decoded Dynamic or ANYVALUE (secsgem wraps polymorphic items)."""
    while isinstance(item, V.Dynamic):
        item = item.value
    return item


def plain(item):
    """The plain Python value of a decoded item or field: ints, text, bools, floats, bytes,
    and lists as lists (nested ones too). A plain Python value is returned as it is.

    >>> plain(typed([["LOT-A", "W01"], ["", ""]]))
    [['LOT-A', 'W01'], ['', '']]
    """
    inner = _unwrap(item)
    if isinstance(inner, V.Array):
        return [plain(element) for element in inner.data]
    if isinstance(inner, V.Binary):
        return bytes(inner.value)  # secsgem gives a single byte as an int
    if inner is None or not hasattr(inner, "get"):
        return inner
    return inner.get()


def is_u1_list(item) -> bool:
    """Whether a decoded item (an ATTRDATA, say) is exactly a list of single U1 values, as
    E87 requires of a SlotMap: False for U4 items, text, a U1 array item <U1 1 0 1> or a
    list nested deeper. An empty list is a list of U1; its length is for the caller to check.

    >>> is_u1_list(typed([1, 3, 300]))
    False
    """
    inner = _unwrap(item)
    if not isinstance(inner, V.Array):
        return False
    for element in inner.data:
        value = _unwrap(element)
        if not isinstance(value, V.U1) or len(value) != 1:
            return False
    return True


def sml(function) -> str:
    """The SML-like text of a secsgem stream function (or of an Undecodable) for a log: one
    line per item as secsgem prints it, without trailing blanks."""
    if function is None:
        return ""
    lines = (line.rstrip() for line in repr(function).splitlines())
    return "\n".join(line for line in lines if line)

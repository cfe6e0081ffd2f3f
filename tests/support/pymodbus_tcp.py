"""pymodbus 3.0 as Debian bookworm ships it, for Modbus TCP. The package imports pyserial
and pyserial-asyncio when it is imported, but Debian's python3-pymodbus does not depend
on them; the serial transports are never used here, so empty stand-ins take their place
when they are not installed."""
import importlib
import sys
import types

for _name in ("serial", "serial_asyncio"):
    try:
        importlib.import_module(_name)
    except ImportError:
        _stand_in = types.ModuleType(_name)
        _stand_in.create_serial_connection = None
        sys.modules[_name] = _stand_in

# pylint: disable=wrong-import-position
from pymodbus.client import ModbusTcpClient  # noqa: E402,F401
from pymodbus.datastore import (ModbusSequentialDataBlock, ModbusServerContext,  # noqa: E402,F401
                                ModbusSlaveContext)
from pymodbus.server import StartTcpServer  # noqa: E402,F401

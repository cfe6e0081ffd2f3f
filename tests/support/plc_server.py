"""A stand-in PLC for the client-mode test: a pymodbus Modbus TCP server on
127.0.0.1:PORT with holding registers 0..199, all 0 at start, answering any unit id.

usage: plc_server.py PORT
"""
import sys

from pymodbus_tcp import (ModbusSequentialDataBlock, ModbusServerContext, ModbusSlaveContext,
                          StartTcpServer)


def main():
    port = int(sys.argv[1])
    registers = ModbusSlaveContext(hr=ModbusSequentialDataBlock(0, [0] * 200), zero_mode=True)
    StartTcpServer(context=ModbusServerContext(slaves=registers, single=True),
                   address=("127.0.0.1", port), allow_reuse_address=True)


if __name__ == "__main__":
    main()

"""The simulated TM5-700: robot model (motion FIFO, kinematics, errors), its faults, event log, virtual camera and
the data table it offers the Ethernet Slave."""

"""The simulator's sockets: the server (one selector, a virtual clock, fair turns between clients) and the TCP
adapters of its ports (Listen node, Ethernet Slave, control channel)."""

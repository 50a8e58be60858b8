"""The simulator's protocols, sans-I/O: frame codecs (pure functions) and the session objects that turn received
bytes into events and replies (Listen node $TMSCT/$TMSTA, Ethernet Slave $TMSVR and its data table)."""

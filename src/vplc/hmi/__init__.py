"""HMI server: serves hmi/ and maps web fields to PLC variables."""

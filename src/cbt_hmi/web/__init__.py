"""HMI server: serves cbt_hmi/pages/ and maps web fields to PLC variables."""

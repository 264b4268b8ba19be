"""The application protocol (``sync``): records of images, control and status, carried in UDP.

:mod:`.fields` is the single definition of every record, shared with the host client.
:class:`.parser.Parser` checks records and hands them on; :class:`.status.StatusReply` answers
status queries.
"""

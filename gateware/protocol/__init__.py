"""The application protocol (``sync``): records of images, control and status, carried in UDP.

:mod:`spec.records` is the single definition of every record, shared with the host client.
:class:`.parser.Parser` checks records and hands them on; :class:`.rows.RowAssembler` turns the
pixels of image records, which may split rows anywhere, into whole rows;
:class:`.status.StatusReply` answers status queries.
"""

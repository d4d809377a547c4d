"""The ``tamp`` parser's command groups, one module each, and the handlers they bind:
`bench` (``tamp bench ...``), `perception` (``tamp perception ...``) and `handlers` (each command's
module imported only when it runs). `tamp.cli.parser.build_parser` puts them together with the
top-level commands; nothing here imports torch or a simulator."""

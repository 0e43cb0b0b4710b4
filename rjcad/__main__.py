from rjcad.cli import main

main()
